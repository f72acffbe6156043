"""A quartz wedge between crossed linear polarisers, lit from behind: the Michel-Levy chart.

The plate (`thinbirefringent`, crystalline quartz with its optic axis in the plate at 45 degrees
to both polarisers) grows linearly in thickness from 0 at the left edge to `max_thickness_um` at
the right, so the retardation (n_e - n_o) d runs through the first interference orders: black,
grey, white, yellow, red, blue, green, ... (quartz: n_e - n_o = 0.0091 at 589 nm, so 120 um
gives about 1.1 um of retardation). Between crossed polarisers a retardation R transmits
sin^2(pi R / lambda) of each wavelength (exactly, up to the plate's Fresnel and multiple
reflections, which the core includes).

Variant: scalar_spectral_polarized (polarisers need the Stokes vector).
"""

from __future__ import annotations

import mitsuba as mi
import numpy as np

VARIANTS = ("scalar_spectral_polarized",)


def scene(width: int = 384, height: int = 128, spp: int = 16, max_thickness_um: float = 120.0,
          crossed: bool = True, filter_bandwidth: float = 0.0) -> dict:
    """The scene as a dict for `mi.load_dict` (call `mi.set_variant` first)."""
    ramp = np.linspace(0.0, 1.0, 512, dtype=np.float32)[None, :].repeat(4, axis=0)
    thickness = {
        "type": "bitmap",
        "bitmap": mi.Bitmap(ramp),
        "raw": True,
        "filter_type": "bilinear",
        "wrap_mode": "clamp",
    }
    def layer(z: float, bsdf: dict) -> dict:
        return {
            "type": "rectangle",
            "to_world": mi.ScalarTransform4f().translate([0, 0, z]).scale([1.5, 0.5, 1.0]),
            "bsdf": bsdf,
        }
    return {
        "type": "scene",
        "integrator": {"type": "volpath", "max_depth": 12},
        "sensor": {
            "type": "orthographic",
            "to_world": mi.ScalarTransform4f().look_at(origin=[0, 0, 5], target=[0, 0, 0], up=[0, 1, 0])
            @ mi.ScalarTransform4f().scale([1.5, 0.5, 1.0]),
            "film": {"type": "hdrfilm", "width": width, "height": height, "rfilter": {"type": "box"},
                     "pixel_format": "rgb"},
            "sampler": {"type": "independent", "sample_count": spp},
        },
        "light": {
            "type": "rectangle",
            "to_world": mi.ScalarTransform4f().translate([0, 0, -2]).scale([3, 3, 1]),
            "emitter": {"type": "area", "radiance": {"type": "d65", "scale": 1.0}},
        },
        "polarizer": layer(-1.0, {"type": "polarizer", "theta": 0.0}),
        "plate": layer(0.0, {
            "type": "thinbirefringent",
            "material": "quartz",
            "optic_axis": [1.0, 1.0, 0.0],
            "thickness": thickness,
            "thickness_scale": max_thickness_um,
            "filter_bandwidth": filter_bandwidth,
        }),
        "analyser": layer(1.0, {"type": "polarizer", "theta": 90.0 if crossed else 0.0}),
    }


#: Gallery options (scenes/gallery.py): a channel render (`render_analytic`: no colour noise;
#: spectral sampling at 8 spp left a chromaticity noise of 0.031 per pixel), docs/scenes.md.
GALLERY = {"analytic": True, "spp": 16}
