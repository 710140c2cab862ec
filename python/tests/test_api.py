"""The package's surface: defaults in step with Rust, the exports, the typed stubs."""

from __future__ import annotations

import dataclasses
import importlib.util
import pathlib
import subprocess
import sys

import pytest

import mlt

ALLOWLIST = pathlib.Path(__file__).with_name("stubtest-allowlist.txt")


def test_value_type_defaults_are_the_rust_defaults() -> None:
    # The dataclasses spell the Rust defaults out; the extension compares them with
    # `RenderSettings::default()`, `Camera::default()` and `Material::diffuse([0.8; 3])`.
    assert mlt._mlt._defaults_mismatches(mlt.RenderSettings(), mlt.Camera(), mlt.Material()) == []
    changed = dataclasses.replace(mlt.RenderSettings(), chains=7)
    mismatches = mlt._mlt._defaults_mismatches(changed, mlt.Camera(), mlt.Material())
    assert [name for name, _, _ in mismatches] == ["RenderSettings"]


def test_every_rust_settings_field_is_a_dataclass_field() -> None:
    # `RenderSettings`' Debug output lists the Rust fields; each must exist in Python.
    (_, _, rust), = mlt._mlt._defaults_mismatches(
        dataclasses.replace(mlt.RenderSettings(), seed=1), mlt.Camera(), mlt.Material()
    )
    names = {part.split(":")[0].strip(" {") for part in rust.split(", ") if ":" in part}
    names = {n.rsplit(" ", 1)[-1] for n in names}
    fields = {f.name for f in dataclasses.fields(mlt.RenderSettings)}
    assert names - fields == set()
    assert len(fields) == len(mlt._mlt._settings_declarations())


def test_algorithm_enum_and_strings_are_interchangeable() -> None:
    assert mlt.Algorithm.PSSMLT_BDPT == "pssmlt-bdpt"
    assert str(mlt.Algorithm.MMLT) == "mmlt"
    settings = mlt.RenderSettings(algorithm=mlt.Algorithm.PATH_SPACE_MLT)
    # Both spellings reach Rust as the same algorithm.
    assert mlt._mlt._defaults_mismatches(
        dataclasses.replace(settings, algorithm="path_space_mlt"), mlt.Camera(), mlt.Material()
    ) == mlt._mlt._defaults_mismatches(settings, mlt.Camera(), mlt.Material())


def test_material_constructors() -> None:
    glass = mlt.Material.dielectric(1.7, abbe_number=36.0)
    assert (glass.kind, glass.ior, glass.abbe_number, glass.color) == ("dielectric", 1.7, 36.0, (1.0, 1.0, 1.0))
    gold = mlt.Material.metallic_roughness((1.0, 0.78, 0.34), 1.0, 0.4, energy_compensation=True)
    assert gold.kind == "metallic_roughness" and gold.energy_compensation
    lamp = mlt.Material.diffuse((0.1, 0.2, 0.3)).with_emission((5, 5, 5))
    assert lamp.emission == (5.0, 5.0, 5.0) and lamp.color == (0.1, 0.2, 0.3)
    sun = mlt.Sun.from_radiance((0, 1, 0), (1.0, 1.0, 1.0), angular_radius_degrees=0.5)
    assert sun.irradiance[0] == pytest.approx(3.14159265 * 0.00872654**2, rel=1e-5)


def test_exports() -> None:
    for name in mlt.__all__:
        assert hasattr(mlt, name), name
    assert issubclass(mlt.InvalidArgumentError, mlt.MltError)
    assert issubclass(mlt.InvalidArgumentError, ValueError)
    assert issubclass(mlt.MltError, RuntimeError)
    assert mlt.__version__


@pytest.mark.skipif(importlib.util.find_spec("mypy") is None, reason="mypy is not installed")
def test_stubs_match_the_extension() -> None:
    # stubtest imports the package and compares every public name, signature and type
    # of `mlt._mlt` (and the pure-Python modules) with the stubs.
    result = subprocess.run(
        [sys.executable, "-m", "mypy.stubtest", "mlt", "--allowlist", str(ALLOWLIST)],
        capture_output=True,
        text=True,
    )
    assert result.returncode == 0, result.stdout + result.stderr
