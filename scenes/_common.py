"""Building blocks shared by the scene modules of this directory (not a scene itself: it has no
`scene` function, so `render.py` and `gallery.py` skip it).

Geometry conventions used by every scene here: the camera is orthographic, looks down -z from
+z with `up` = +y, so image columns run along +x and image rows along -y; optical elements are
`rectangle`s parallel to the xy-plane ("layers"), whose local shading frame is (x, y, z) of the
world (a rectangle's s axis is its dp/du, the world x axis when it is only translated and
scaled). Hence a Mitsuba `polarizer` layer with `theta` transmits along the world direction at
angle -theta from x (counter-clockwise seen from the camera; see docs/mitsuba.md §5 for Mitsuba's
conventions), and a plate's `axis_angle` is counter-clockwise from x seen from the camera.

A `bitmap` texture on a rectangle maps its array row 0 to the rectangle's bottom edge (y = -1
in the rectangle's frame) and column 0 to the left edge (measured in Mitsuba 3.9.1); the
helpers below take arrays in that order (row index growing with y).
"""

from __future__ import annotations

import mitsuba as mi
import numpy as np


def T():
    """A fresh `mi.ScalarTransform4f` of the current variant (looked up at call time: scene
    modules are imported before a variant is set)."""
    return mi.ScalarTransform4f()


def layer(z: float, half_x: float, half_y: float, bsdf: dict, centre_x: float = 0.0,
          centre_y: float = 0.0) -> dict:
    """A rectangle parallel to the xy-plane at height z, normal +z (towards the camera)."""
    return {
        "type": "rectangle",
        "to_world": T().translate([centre_x, centre_y, z]).scale([half_x, half_y, 1.0]),
        "bsdf": bsdf,
    }


def data_texture(values: np.ndarray, filter_type: str = "bilinear") -> dict:
    """A raw (unconverted) single-channel bitmap texture; `values[i, j]`: row i grows with y."""
    return {
        "type": "bitmap",
        "bitmap": mi.Bitmap(np.ascontiguousarray(values, dtype=np.float32)),
        "raw": True,
        "filter_type": filter_type,
        "wrap_mode": "clamp",
    }


def stressed_plate(index: float, thickness_mm: float, dsigma: np.ndarray, angle: np.ndarray,
                   stress_optic_per_pa: float, filter_bandwidth: float,
                   angle_filter: str = "bilinear") -> dict:
    """A `thinbirefringent` plate of glass (index `index`) under plane stress: n_e - n_o =
    C (sigma_1 - sigma_2) from the principal stress difference `dsigma` (MPa) with the optic
    axis along the principal direction `angle` (degrees), both textures over the plate."""
    return {
        "type": "thinbirefringent",
        "eta_o": index,
        "eta_e": index,
        "thickness": thickness_mm * 1e3,
        "birefringence": data_texture(dsigma),
        "birefringence_scale": stress_optic_per_pa * 1e6,
        "axis_angle": data_texture(angle, filter_type=angle_filter),
        "filter_bandwidth": filter_bandwidth,
    }


def monochromatic_srf(wavelength_nm: float, width_nm: float = 0.01) -> dict:
    """A sensor response that is non-zero only within +-width/2 of `wavelength_nm`: spectral
    variants then sample every wavelength of a path inside that band (a monochromatic camera)."""
    return {
        "type": "regular",
        "wavelength_min": wavelength_nm - width_nm / 2,
        "wavelength_max": wavelength_nm + width_nm / 2,
        "values": "1, 1",
    }


def camera(kind: str, to_world, width: int, height: int, spp: int,
           wavelength_nm: float | None = None, single_channel: bool = True,
           crop: tuple[int, int, int, int] | None = None, **options) -> dict:
    """A sensor of type `kind` (with `options`, e.g. a perspective camera's `fov`), a box-filtered
    film of width x height pixels and the independent sampler. `wavelength_nm` makes it
    monochromatic: with `single_channel` a one-channel `specfilm` whose band is
    `monochromatic_srf` (the radiance in that band), otherwise an RGB `hdrfilm` on a sensor with
    that response (the layout the `stokes` integrator needs; in Mitsuba 3.9.1 `stokes` with a
    `specfilm` crashes, and an `hdrfilm`'s own RGB channels come out near 0 with a narrow sensor
    response, while the `stokes` S0..S3 channels are right). `crop` = (offset_x, offset_y,
    width, height) renders only that window of the film."""
    if wavelength_nm is not None and single_channel:
        film = {"type": "specfilm", "band": monochromatic_srf(wavelength_nm)}
    else:
        film = {"type": "hdrfilm", "pixel_format": "rgb"}
    film.update({"width": width, "height": height, "rfilter": {"type": "box"}})
    if crop is not None:
        film.update({"crop_offset_x": crop[0], "crop_offset_y": crop[1], "crop_width": crop[2],
                     "crop_height": crop[3]})
    sensor = {"type": kind, **options, "to_world": to_world, "film": film,
              "sampler": {"type": "independent", "sample_count": spp}}
    if wavelength_nm is not None and not single_channel:
        sensor["srf"] = monochromatic_srf(wavelength_nm)
    return sensor


def ortho_sensor(width: int, height: int, spp: int, half_x: float, half_y: float,
                 wavelength_nm: float | None = None, z: float = 10.0,
                 single_channel: bool = True, crop: tuple[int, int, int, int] | None = None) -> dict:
    """Orthographic camera at height z looking down -z, seeing [-half_x, half_x] x [-half_y,
    half_y] (film and monochromatic options: `camera`)."""
    # Mitsuba's orthographic camera sees [-1, 1] x [-1/aspect, 1/aspect] in its own frame
    # (aspect = width / height): scale y by the aspect to see +-half_y.
    to_world = (T().look_at(origin=[0, 0, z], target=[0, 0, 0], up=[0, 1, 0])
                @ T().scale([half_x, half_y * width / height, 1.0]))
    return camera("orthographic", to_world, width, height, spp, wavelength_nm, single_channel, crop)


def lens_sensor(width: int, height: int, spp: int, fov_deg: float, z: float,
                wavelength_nm: float | None = None, single_channel: bool = True,
                crop: tuple[int, int, int, int] | None = None) -> dict:
    """Perspective camera at height z looking down -z (image up = +y) with a lens of `fov_deg`
    across the image's width (film and monochromatic options: `camera`)."""
    to_world = T().look_at(origin=[0, 0, z], target=[0, 0, 0], up=[0, 1, 0])
    return camera("perspective", to_world, width, height, spp, wavelength_nm, single_channel, crop,
                  fov=fov_deg, fov_axis="x")


def backlight(z: float, half: float, scale: float = 1.0, black: bool = False) -> dict:
    """A large D65 area light facing +z (white light from behind the optical train). Mitsuba
    gives a shape without a BSDF a grey diffuse one (reflectance 0.5), which sends light that the
    optics reflect back down into the view again; `black` makes the light box reflect nothing."""
    light = {
        "type": "rectangle",
        "to_world": T().translate([0, 0, z]).scale([half, half, 1.0]),
        "emitter": {"type": "area", "radiance": {"type": "d65", "scale": scale}},
    }
    if black:
        light["bsdf"] = {"type": "diffuse", "reflectance": 0.0}
    return light


def pixel_centres(n: int, half: float) -> np.ndarray:
    """World coordinate of the centres of n pixels spanning [-half, half]."""
    return -half + (np.arange(n) + 0.5) * (2 * half / n)
