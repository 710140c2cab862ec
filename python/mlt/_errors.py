"""The exceptions mlt raises. Defined in Python (the extension raises them by name) so that
an invalid argument can be both an :class:`MltError` and a :class:`ValueError`."""

from __future__ import annotations

from typing import Optional


class MltError(RuntimeError):
    """An error from mlt: ``status`` names it as the C API's ``MLT_STATUS_*`` does, in
    lower case without the prefix (``"invalid_argument"``, ``"unsupported"``,
    ``"out_of_memory"``, ``"internal_error"``), or ``"load_error"`` for a scene file that
    cannot be read; ``code`` is the C status value (None for a load error); ``message``
    names the offending field, index and value."""

    status: str
    code: Optional[int]
    message: str

    def __init__(self, status: str, code: Optional[int], message: str) -> None:
        super().__init__(f"{status.replace('_', ' ')}: {message}")
        self.status = status
        self.code = code
        self.message = message

    def __reduce__(self):  # type: ignore[no-untyped-def]
        # Picklable with its fields (errors cross process boundaries in distributed use).
        return (type(self), (self.status, self.code, self.message))


class InvalidArgumentError(MltError, ValueError):
    """A value mlt was given is invalid (a shape, a dtype, a NaN, an index out of range,
    a setting out of its limits): ``status == "invalid_argument"``."""


class UnsupportedError(MltError):
    """Valid, but not supported by this build (the Embree backend without the feature):
    ``status == "unsupported"``."""


class LoadError(MltError):
    """A scene or environment file cannot be read or is malformed: ``status ==
    "load_error"``; the message names the file."""


__all__ = ["InvalidArgumentError", "LoadError", "MltError", "UnsupportedError"]
