"""A thin birefringent film on glass, seen in reflection: iridescent thin-film colours.

The supplemental's section 3 ("Iridescence when reflecting off an anisotropic slab"): an x-cut
lithium niobate film (the core's dispersive `linbo3`, n_o = 2.29, n_e = 2.20 at 600 nm; optic
axis in the film plane, along x) on fused silica (`exit_ior` 1.458), as in "lithium niobate on
insulator" wafers. Its thickness varies over the object like a draining soap film, from 0.1 um
at the top edge to `max_thickness_um` (0.8 um) at the bottom, with a slow swirl; the reflected
colours run through the thin-film interference orders (Newton's colours), modified by the
birefringence (the o and e waves have different optical thicknesses, so the colours depend on
the azimuth of the plane of incidence relative to the optic axis).

Geometry: the film is a 2 x 2 rectangle at z = 0 seen by a perspective camera 40 degrees from
its normal; a large rectangular D65 area light sits at the camera's mirror position, so that
every pixel sees the film's specular reflection of the light (radiance `light_scale` times D65,
3 by default so that the film's reflectance (about 5 to 30 %) gives mid-grey pixels). The
substrate is black glass (`black_substrate`, default): silica's index at the film's bottom
interface, and whatever enters the substrate is absorbed (`absorbing_exit`), so the image is
the film's reflectance times the light, with no sampling noise from choosing between the
reflected and the transmitted lobe; `thinbirefringent` computes the whole plate (both
interfaces and every internal reflection). With `black_substrate=False` the transmitted light
leaves through the substrate into empty space (a black background): the same mean image, but
each sample picks reflection or transmission at random.

Variants: scalar_rgb (the plate integrated in closed form over the sRGB channels: noise-free
colour), scalar_spectral (4 sampled wavelengths per path, each through a Gaussian band of
`filter_bandwidth`), scalar_spectral_polarized (the same with Mueller matrices). The first is
the default.
"""

from __future__ import annotations

import mitsuba as mi
import numpy as np

VARIANTS = ("scalar_rgb", "scalar_spectral", "scalar_spectral_polarized")

#: The film's crystal (the core's catalogue).
MATERIAL = "linbo3"
#: Substrate index (fused silica, Mitsuba's "fused quartz").
SUBSTRATE_IOR = 1.458
#: Thickness range of the film (micrometres).
MIN_THICKNESS_UM, MAX_THICKNESS_UM = 0.1, 0.8


def thickness_profile(n: int = 256) -> np.ndarray:
    """Film thickness in [0, 1] (times `MAX_THICKNESS_UM`) on an n x n grid (row 0 = top, v = 0).

    A draining film thickens downwards (d ~ v^1.4) and carries a slow swirl (a sinusoidal
    perturbation of 8 % of the range); clamped to [MIN/MAX, 1].
    """
    v, u = np.meshgrid(np.linspace(0.0, 1.0, n), np.linspace(0.0, 1.0, n), indexing="ij")
    d = v ** 1.4 + 0.08 * np.sin(2.0 * np.pi * (1.3 * u + 0.6 * v)) * np.sin(np.pi * v)
    return np.clip(d, MIN_THICKNESS_UM / MAX_THICKNESS_UM, 1.0).astype(np.float32)


def scene(width: int = 256, height: int = 256, spp: int = 16, filter_bandwidth: float = 0.0,
          max_thickness_um: float = MAX_THICKNESS_UM, optic_axis=(1.0, 0.0, 0.0),
          camera_angle_deg: float = 40.0, light_scale: float = 3.0,
          black_substrate: bool = True) -> dict:
    """The scene as a dict for `mi.load_dict` (call `mi.set_variant` first)."""
    T = mi.ScalarTransform4f
    a = np.radians(camera_angle_deg)
    camera = [0.0, -4.0 * np.sin(a), 4.0 * np.cos(a)]
    mirror = [0.0, 4.0 * np.sin(a), 4.0 * np.cos(a)]
    return {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 3},
        "sensor": {
            "type": "perspective",
            "fov": 22.0,
            "to_world": T().look_at(origin=camera, target=[0, 0, 0], up=[0, 0, 1]),
            "film": {"type": "hdrfilm", "width": width, "height": height,
                     "rfilter": {"type": "box"}, "pixel_format": "rgb"},
            "sampler": {"type": "independent", "sample_count": spp},
        },
        # Large enough that every reflected ray of the visible film ends on it.
        "light": {
            "type": "rectangle",
            "to_world": T().look_at(origin=mirror, target=[0, 0, 0], up=[0, 0, 1]).scale(4.0),
            "emitter": {"type": "area", "radiance": {"type": "d65", "scale": light_scale}},
        },
        "film": {
            "type": "rectangle",
            "bsdf": {
                "type": "thinbirefringent",
                "material": MATERIAL,
                "ext_ior": 1.0,
                "exit_ior": SUBSTRATE_IOR,
                "optic_axis": list(optic_axis),
                "thickness": {"type": "bitmap", "bitmap": mi.Bitmap(thickness_profile()),
                              "raw": True, "filter_type": "bilinear", "wrap_mode": "clamp"},
                "thickness_scale": max_thickness_um,
                "filter_bandwidth": filter_bandwidth,
                "absorbing_exit": black_substrate,
            },
        },
    }


#: Gallery options (scenes/gallery.py): the scene's scalar_rgb render integrates the film over
#: the sRGB channels in closed form; 4 spp antialias its fringes (0.06 % of brightness noise
#: per pixel at 16 spp), docs/scenes.md.
GALLERY = {"spp": 4}
