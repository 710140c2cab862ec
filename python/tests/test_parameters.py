"""Every render setting declared in Rust (``src/render/settings.rs``) is a keyword of
``mlt.RenderSettings`` with the declared default, and a value outside its range is refused
with the message every front end gives."""

from __future__ import annotations

import dataclasses

import pytest
from conftest import CAMERA, quad

import mlt


def test_every_setting_is_a_keyword_with_its_default_and_message() -> None:
    positions, indices = quad()
    scene = mlt.Scene.from_arrays(positions, indices)
    declared = mlt._mlt._settings_declarations()
    assert [name for name, _, _, _ in declared] == [f.name for f in dataclasses.fields(mlt.RenderSettings)]
    defaults = mlt.RenderSettings()
    for name, default, outside, message in declared:
        assert getattr(defaults, name) == default, name
        if outside is None:
            continue
        with pytest.raises(mlt.InvalidArgumentError) as error:
            mlt.render(scene, CAMERA, mlt.RenderSettings(**{name: outside}))
        assert error.value.message == message, name


def test_every_material_parameter_is_a_keyword_with_its_default_and_message() -> None:
    """Every material parameter declared in Rust (``src/scene/material.rs``) is a field of
    ``mlt.Material`` with the declared default, and a value outside its range is refused with
    the message every front end gives."""
    positions, indices = quad()
    declared = mlt._mlt._material_declarations()
    assert [name for name, _, _, _ in declared] == [f.name for f in dataclasses.fields(mlt.Material)]
    defaults = mlt.Material()
    for name, default, outside, message in declared:
        assert getattr(defaults, name) == default, name
        if outside is None:
            continue
        with pytest.raises(mlt.InvalidArgumentError) as error:
            mlt.Scene.from_arrays(positions, indices, materials=[mlt.Material(**{name: outside})])
        assert error.value.message == message, name
