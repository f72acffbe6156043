"""The XML versions of the scenes (scenes/<name>.xml) load and render the same image as the Python
dicts of their modules at the default physics parameters (small images, few samples: the check
is that both describe the same scene, not the image quality).

Tolerance: the same scene with the same seed gives the same samples, so the images agree to
float rounding (textures read back from float EXRs are bit-identical; transforms composed by the
XML parser and by ScalarTransform4f differ in the last bits): 1e-4 relative to the image's mean.
"""

import pathlib
import re
import sys

import mitsuba as mi
import numpy as np
import pytest

import mitsuba_birefringent  # noqa: F401

SCENES = pathlib.Path(__file__).resolve().parents[2] / "scenes"
sys.path.insert(0, str(SCENES))

# name: (width, height) of the XML's aspect; spp
CASES = {"photoelastic_disk": (32, 32), "calcite_rhomb": (36, 24), "waveplates": (48, 16),
         "train_window": (36, 24), "conoscope": (24, 24)}


@pytest.mark.parametrize("name", sorted(CASES))
def test_xml_matches_python(name):
    import importlib

    module = importlib.import_module(name)
    mi.set_variant(module.VARIANTS[0])
    if hasattr(module, "write_data"):
        module.write_data()
    width, height = CASES[name]
    size = dict(width=width, height=height, spp=4)
    # The XML's default sampler is multijitter (as scenes/render.py renders); the modules' own is
    # independent.
    xml = mi.load_file(str(SCENES / f"{name}.xml"), sampler="independent", **size)
    from_xml = np.array(mi.render(xml, seed=11))
    from_py = np.array(mi.render(mi.load_dict(module.scene(**size)), seed=11))
    assert from_xml.shape == from_py.shape
    scale = np.abs(from_py).mean()
    assert scale > 0
    diff = np.abs(from_xml - from_py).max() / scale
    print(f"{name}: max |xml - python| / mean = {diff:.2e}")
    assert diff < 1e-4, diff


def test_waveplate_thicknesses_in_xml_are_the_design_values():
    import waveplates

    text = (SCENES / "waveplates.xml").read_text()
    for key, fraction in (("qwp_thickness", 0.25), ("hwp_thickness", 0.5)):
        value = float(re.search(rf'<default name="{key}" value="([^"]+)"/>', text).group(1))
        # 1e-12 relative: the XML holds the calculator's value printed with 17 digits.
        assert abs(value / waveplates.plate_thickness_um(fraction) - 1) < 1e-12, key
