"""Invalid parameters fail at scene load with a message naming the parameter; the package
registers the plugins in every supported variant and refuses the others clearly."""

from __future__ import annotations

import math

import drjit as dr
import numpy as np
import pytest

import mitsuba as mi
import mitsuba_birefringent

from bfr_helpers import POLARIZED, variant

COMMON_CASES = [
    ({"eta_o": 0.0, "eta_e": 1.5}, "eta_o"),
    ({"eta_o": 1.5, "eta_e": -1.0}, "eta_e"),
    ({"eta_o": math.nan, "eta_e": 1.5}, "eta_o"),
    ({"eta_o": 1.5, "eta_e": math.inf}, "eta_e"),
    ({"eta_o": 1.5}, "eta_e"),
    ({"eta_e": 1.5}, "eta_o"),
    ({"eta_o": "glass", "eta_e": 1.5}, "eta_o"),
    ({"material": "unobtainium"}, "material"),
    ({"material": 3.0}, "material"),
    ({"material": "calcite", "eta_o": 1.5, "eta_e": 1.6}, "material"),
    ({"material": "calcite", "kappa_o": -0.1}, "kappa_o"),
    ({"material": "calcite", "kappa_e": math.nan}, "kappa_e"),
    ({"material": "calcite", "kappa_e": 1e300}, "kappa_e"),  # was named eta_e
    ({"eta_o": 1.5, "eta_e": 1.5, "kappa_o": 1e4}, "kappa_o"),  # was named eta_o
    ({"material": ""}, "material"),  # was read as constant indices 0: eta_o
    ({"material": "calcite", "optic_axis": [0, 0, 0]}, "optic_axis"),
    ({"material": "calcite", "optic_axis": [math.nan, 0, 1]}, "optic_axis"),
    ({"material": "calcite", "optic_axis": "up"}, "optic_axis"),
    ({"material": "calcite", "ext_ior": "unobtainium"}, "ext_ior"),
    ({"material": "calcite", "ext_ior": -1.0}, "ext_ior"),
    ({"material": "calcite", "ext_ior": math.nan}, "ext_ior"),
    ({"material": "calcite", "no_such_parameter": 1.0}, "no_such_parameter"),
]

PLATE_CASES = [
    ({"thickness": -1.0}, "thickness"),
    ({"thickness": math.nan}, "thickness"),
    ({"thickness": 2.0, "thickness_scale": -1.0}, "thickness"),
    ({"thickness": "thick"}, "thickness"),
    ({"exit_ior": 0.0}, "exit_ior"),
    ({"exit_ior": "unobtainium"}, "exit_ior"),
    ({"filter_bandwidth": -2.0}, "filter_bandwidth"),
    ({"filter_bandwidth": math.nan}, "filter_bandwidth"),
    ({"birefringence": math.nan}, "birefringence"),
    ({"axis_angle": math.nan}, "axis_angle"),
    ({"axis_angle": math.inf}, "axis_angle"),
    ({"eta_o": 1.5, "eta_e": 1.5, "birefringence": -2.0}, "birefringence"),
]


# A physical scalar given as a colour: refused in every variant, with how to give it.
COLOUR_VALUES = {
    "rgb": {"type": "rgb", "value": [30.0, 30.0, 31.0]},
    "spectrum": {"type": "spectrum", "value": [(400.0, 30.0), (700.0, 31.0)]},
    "srgb texture": {"type": "srgb", "color": [0.5, 0.5, 0.5]},
    "string": "thick",
}


@pytest.mark.parametrize("name", ["scalar_rgb", "scalar_spectral", POLARIZED])
@pytest.mark.parametrize("param", ["thickness", "axis_angle", "birefringence"])
@pytest.mark.parametrize("kind", sorted(COLOUR_VALUES))
def test_scalar_parameter_given_as_a_colour_is_refused(name, param, kind):
    variant(name)
    with pytest.raises(RuntimeError) as e:
        load("thinbirefringent", {"material": "quartz", param: COLOUR_VALUES[kind]})
    text = str(e.value)
    assert f'"{param}"' in text and 'raw="true"' in text and "give a float" in text, text


@pytest.mark.parametrize("name", ["scalar_spectral", POLARIZED])
def test_colour_bitmap_is_refused_at_load_in_spectral_variants(name):
    """A 3-channel bitmap without raw="true" holds upsampled spectra in the spectral variants
    and Mitsuba refuses its eval_1: refused at load, naming the parameter (before: an
    exception at the first hit, in the middle of a render). With raw="true" it loads."""
    variant(name)
    data = mi.Bitmap(np.full((2, 2, 3), 3.0, dtype=np.float32))
    with pytest.raises(RuntimeError, match='"thickness".*raw="true"'):
        load("thinbirefringent", {"material": "quartz", "thickness": {"type": "bitmap", "bitmap": data}})
    load("thinbirefringent", {"material": "quartz",
                              "thickness": {"type": "bitmap", "bitmap": data, "raw": True}})


# Messages name the parameter the user wrote, in the user's unit (not the core's name, unit or
# the Mitsuba type it was read as).
EXACT_MESSAGES = [
    ({"axis_angle": math.nan}, "axis_angle: must be a finite number (degrees), got NaN", "optic_axis"),
    ({"ext_ior": {"type": "rgb", "value": [1.5, 1.5, 1.5]}},
     '"ext_ior" must be a float (a real index) or one of Mitsuba\'s IOR names', "expected string"),
    ({"exit_ior": [1.0, 2.0, 3.0]},
     '"exit_ior" must be a float (a real index) or one of Mitsuba\'s IOR names', "expected string"),
    ({"thickness": 2e6}, "thickness: must be within [0, 1e6] µm (1 m), got 2000000 µm", " nm"),
    ({"filter_bandwidth": 200.0},
     "filter_bandwidth: must be within [0, 137.5] nm (a quarter of the wavelength 550 nm), got 200 nm",
     "wavelength /"),
]


@pytest.mark.parametrize("params,want,not_want", EXACT_MESSAGES)
def test_message_names_what_the_user_wrote(params, want, not_want):
    variant(POLARIZED)
    with pytest.raises(RuntimeError) as e:
        load("thinbirefringent", {"material": "quartz", **params})
    assert want in str(e.value) and not_want not in str(e.value), str(e.value)


@pytest.mark.parametrize("kappa", ["kappa_o", "kappa_e"])
def test_absorbing_birefringent_crystal_names_the_kappa_given(kappa):
    variant(POLARIZED)
    with pytest.raises(RuntimeError) as e:
        load("birefringent", {"material": "calcite", kappa: 0.1})
    assert f"{kappa}: an absorbing birefringent crystal" in str(e.value), str(e.value)


def test_axis_angle_bitmap_with_nan_is_named():
    """An axis-angle bitmap with a NaN cell (its mean, the load check's value, is NaN) is
    refused naming axis_angle, not the optic axis the shim rotates with it."""
    variant(POLARIZED)
    angle = mi.Bitmap(np.array([[30.0, math.nan]], dtype=np.float32))
    with pytest.raises(RuntimeError) as e:
        load("thinbirefringent", {"material": "quartz",
                                  "axis_angle": {"type": "bitmap", "bitmap": angle, "raw": True}})
    assert "axis_angle: must be a finite number" in str(e.value), str(e.value)


def load(kind, params):
    return mi.load_dict({"type": kind, **params})


@pytest.mark.parametrize("kind", ["thinbirefringent", "birefringent"])
@pytest.mark.parametrize("params,name", COMMON_CASES)
def test_invalid_parameter_is_named(kind, params, name):
    variant(POLARIZED)
    with pytest.raises(RuntimeError) as e:
        load(kind, params)
    assert name in str(e.value), str(e.value)


@pytest.mark.parametrize("params,name", PLATE_CASES)
def test_invalid_plate_parameter_is_named(params, name):
    variant(POLARIZED)
    with pytest.raises(RuntimeError) as e:
        load("thinbirefringent", {"material": "quartz", **params} if "eta_o" not in params else params)
    assert name in str(e.value), str(e.value)


@pytest.mark.parametrize("kind", mitsuba_birefringent.PLUGINS)
@pytest.mark.parametrize("name", mitsuba_birefringent.VARIANTS)
def test_registered_in_every_supported_variant(kind, name):
    """Every plugin loads in every variant the package lists; a CUDA variant only where a CUDA
    device exists (test_cuda_variants_refuse_host_queries_clearly: what it refuses there)."""
    if name.startswith("cuda_") and not dr.has_backend(dr.JitBackend.CUDA):
        pytest.skip("no CUDA device on this machine")
    variant(name)
    glass = {"eta_o": 1.5, "eta_e": 1.5}
    desc = {"layer": {"type": "thinbirefringent", **glass}} if kind == "birefringentstack" else glass
    if name.startswith("cuda_") and "spectral" not in name and kind != "birefringent":
        with pytest.raises(RuntimeError, match="cuda_ad_spectral"):
            load(kind, desc)
        return
    assert isinstance(load(kind, desc), mi.BSDF)


def test_cuda_variants_refuse_host_queries_clearly():
    """In a CUDA variant a plate's query over colour channels would need the host: refused at
    load, naming the variants that run it (the spectral cuda ones at exact wavelengths, the
    llvm ones for the integral); only where a CUDA device lets Mitsuba set the variant."""
    if not dr.has_backend(dr.JitBackend.CUDA):
        pytest.skip("no CUDA device on this machine")
    try:
        variant("cuda_ad_rgb")
        with pytest.raises(RuntimeError, match="cuda_ad_spectral.*llvm_ad"):
            load("thinbirefringent", {})
    finally:
        variant(POLARIZED)


def test_defaults_load():
    variant(POLARIZED)
    p = load("thinbirefringent", {})
    c = load("birefringent", {})
    assert "calcite" in str(p) and "calcite" in str(c)
    assert mitsuba_birefringent.core_version()


# With constant indices the core receives eta_o + i kappa_o and names "eta_o" when kappa_o is
# invalid ("eta_o: extinction coefficient (imaginary part) must be >= 0 ..., got -0.1"); with a
# named crystal it names "kappa_o". Reported to the core.
@pytest.mark.parametrize("params,name", [({"kappa_o": -0.1}, "kappa_o"), ({"kappa_e": math.nan}, "kappa_e")])
def test_constant_material_kappa_is_named(params, name):
    variant(POLARIZED)
    with pytest.raises(RuntimeError) as e:
        load("thinbirefringent", {"eta_o": 1.5, "eta_e": 1.5, **params})
    assert name in str(e.value), str(e.value)
