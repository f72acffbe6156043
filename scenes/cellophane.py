"""Cellophane art: overlapping strips of cellophane on a light box between crossed polarisers.

What it shows: strips of cellophane film laid on a light box (white, D65) between a polariser
along x and an analyser along y (`analyser_deg` 90: crossed; 0: parallel, the complementary
colours). On the left a staircase of three parallel strips at 45 degrees shows one, two and three
layers (grey-white, orange, blue: the first orders of the Michel-Levy chart), and a strip at -45
degrees across it takes one layer away wherever it crosses (crossed slow axes: the retardations
subtract; one on one is black). On the right two strips at 60 degrees overlap along half their
width (one and two layers), a strip at 15 degrees crosses one of them (two layers at 45 degrees
to each other: neither adds nor subtracts) and one at -35 degrees crosses both (nearly crossed
axes: nearly black).

The physics: cellophane (regenerated cellulose, index about 1.5) is stretched in manufacture
and becomes birefringent with its slow axis along the stretch, here along each strip's length;
a film of thickness d = 25 um with n_e - n_o = 0.009 retards by 225 nm. A stack of films is a
`birefringentstack` wherever strips overlap: one plugin evaluates every layer that lies over a
point, with all internal reflections, in the order the strips were laid (the last one on top,
nearest the camera). Each layer of the stack is a "slot": its `thickness` is a texture that is
the film's thickness inside the strips assigned to that slot and 0 elsewhere (a layer of zero
thickness is optically absent), its `axis_angle` a texture of those strips' angles; strips that
overlap get different slots, a strip laid later a higher slot than any strip under it
(`slots`): here 4 slots, as many as the most strips over one point (a zero-thickness layer
still costs its share of the stack's evaluation, so the strips are arranged to need few). Between crossed
polarisers a layer of retardation R at angle a to the polariser transmits
sin^2(2 a) sin^2(pi R / lambda) of each wavelength (Jones calculus, ideal retarder); layers at
other angles multiply as Jones matrices.

The check (tests/python/test_scene_cellophane.py): the colour of one layer and of two
overlapping layers in a channel render (`render_analytic`) against the calculator's stack
(`birefringence stack`, integrated over the same sRGB channels) and against an independent
transfer-matrix calculation in the test (the layers' characteristic matrices at normal
incidence, every internal reflection, on a dense wavelength grid with Mitsuba's colour matching).

Variant: scalar_spectral_polarized (polarisers need the Stokes vector); render it by colour
channels (`scenes/render.py cellophane --analytic`, as the gallery does): the stack is the one
plate on every path, so the channel render is exact and has no colour noise.
"""

from __future__ import annotations

import functools
import math
import typing

import numpy as np

from _common import T, backlight, data_texture, layer, ortho_sensor

VARIANTS = ("scalar_spectral_polarized",)

#: The view (and the light box) spans [-VIEW_X, VIEW_X] x [-VIEW_Y, VIEW_Y].
VIEW_X, VIEW_Y = 1.5, 1.0
#: Texels of the slot textures over the view (nearest filtering: sharp strip edges).
TEXELS = (1200, 800)
#: Cellophane film: thickness (um), ordinary index and birefringence n_e - n_o (module docstring).
THICKNESS_UM, INDEX, BIREFRINGENCE = 25.0, 1.5, 0.009


class Strip(typing.NamedTuple):
    """A strip of film: centre (x, y), half length and half width (scene units), and the angle of
    its length (degrees, counter-clockwise from x seen from the camera), which is its slow axis."""

    x: float
    y: float
    half_length: float
    half_width: float
    angle_deg: float

    def edge_distance(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Signed distance of points (x, y) to the strip's edge: positive inside."""
        t = math.radians(self.angle_deg)
        dx, dy = x - self.x, y - self.y
        along = dx * math.cos(t) + dy * math.sin(t)
        across = -dx * math.sin(t) + dy * math.cos(t)
        return np.minimum(self.half_length - np.abs(along), self.half_width - np.abs(across))

    def inside(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Whether points (x, y) lie inside the strip."""
        return self.edge_distance(x, y) > 0


#: The strips, in the order they are laid on the light box (the last on top).
STRIPS = (
    # Left, the staircase: three parallel strips at 45 degrees, each shifted across by a third
    # of its width: one, two, three, two, one layers.
    Strip(-0.62, 0.12, 0.92, 0.28, 45.0),
    Strip(-0.48, -0.02, 0.92, 0.28, 45.0),
    Strip(-0.34, -0.16, 0.92, 0.28, 45.0),
    # Across it at -45 degrees: subtracts one layer where it crosses.
    Strip(-0.58, -0.12, 0.85, 0.13, -45.0),
    # Right: two strips at 60 degrees overlapping along half their width, one at 15 degrees and
    # one at -35 degrees across them.
    Strip(0.86, 0.0, 0.95, 0.17, 60.0),
    Strip(1.02, -0.08, 0.95, 0.17, 60.0),
    Strip(1.05, 0.45, 0.45, 0.13, 15.0),
    Strip(0.98, -0.45, 0.55, 0.13, -35.0),
)


def texel_centres() -> tuple[np.ndarray, np.ndarray]:
    """World (x, y) of the texel centres, arrays of shape (rows, columns), row 0 at y = -VIEW_Y
    (a bitmap's row 0 maps to the rectangle's bottom edge: scenes/_common.py)."""
    nx, ny = TEXELS
    xs = -VIEW_X + (np.arange(nx) + 0.5) * 2 * VIEW_X / nx
    ys = -VIEW_Y + (np.arange(ny) + 0.5) * 2 * VIEW_Y / ny
    return np.meshgrid(xs, ys)


@functools.lru_cache(maxsize=None)
def edge_distances() -> np.ndarray:
    """(strips, rows, columns): each texel centre's signed distance to each strip's edge."""
    x, y = texel_centres()
    return np.array([s.edge_distance(x, y) for s in STRIPS])


@functools.lru_cache(maxsize=None)
def coverage() -> np.ndarray:
    """(strips, rows, columns): whether each texel centre lies inside each strip of STRIPS."""
    return edge_distances() > 0


def slots() -> list[int]:
    """The stack layer ("slot") of each strip of STRIPS, counted from the bottom: one more than
    the highest slot of the strips laid before it that it overlaps (so at every point the layers
    keep the order in which the strips were laid, and overlapping strips never share a slot)."""
    inside = coverage()
    out: list[int] = []
    for k in range(len(STRIPS)):
        below = [out[j] for j in range(k) if (inside[j] & inside[k]).any()]
        out.append(max(below) + 1 if below else 0)
    return out


def slot_textures() -> list[tuple[np.ndarray, np.ndarray]]:
    """Per slot, from the bottom: (thickness fraction, angle) over the texels: 1 inside a strip
    of the slot and 0 elsewhere, the strip's angle there (0 elsewhere)."""
    inside = coverage()
    assigned = slots()
    out = []
    for slot in range(max(assigned) + 1):
        fraction = np.zeros(inside.shape[1:], dtype=np.float32)
        angle = np.zeros(inside.shape[1:], dtype=np.float32)
        for k, s in enumerate(STRIPS):
            if assigned[k] == slot:
                fraction[inside[k]] = 1.0
                angle[inside[k]] = s.angle_deg
        out.append((fraction, angle))
    return out


def film(thickness_um: float = THICKNESS_UM, index: float = INDEX,
         birefringence: float = BIREFRINGENCE) -> dict:
    """The constants of one film layer (`thinbirefringent` parameters)."""
    return {"type": "thinbirefringent", "eta_o": index, "eta_e": index + birefringence,
            "thickness_scale": thickness_um}


def stack(filter_bandwidth: float = 0.0, **film_options) -> dict:
    """The `birefringentstack` of every slot, from the exterior (the camera's side: the top slot)
    down."""
    layers = {}
    for k, (fraction, angle) in reversed(list(enumerate(slot_textures()))):
        layers[f"slot_{k}"] = dict(film(**film_options), thickness=data_texture(fraction, "nearest"),
                                   axis_angle=data_texture(angle, "nearest"))
    return {"type": "birefringentstack", "filter_bandwidth": filter_bandwidth, **layers}


def covering(x: np.ndarray, y: np.ndarray) -> list[tuple[int, ...]]:
    """The strips over each point (x, y), from the top (the camera's side) down."""
    inside = [s.inside(x, y) for s in STRIPS]
    return [tuple(k for k in reversed(range(len(STRIPS))) if inside[k][i]) for i in range(len(x))]


def probe(strips: tuple[int, ...]) -> tuple[float, float, float]:
    """The texel centre covered by exactly `strips` (indices into STRIPS, any order) that lies
    farthest from every strip edge: (x, y, its distance to the nearest edge)."""
    x, y = (a.ravel() for a in texel_centres())
    distance = edge_distances().reshape(len(STRIPS), -1)
    wanted = np.zeros(len(STRIPS), dtype=bool)
    wanted[list(strips)] = True
    exact = np.all((distance > 0) == wanted[:, None], axis=0)
    if not exact.any():
        raise ValueError(f"no point lies under exactly the strips {strips}")
    clearance = np.where(exact, np.abs(distance).min(axis=0), -np.inf)
    best = int(np.argmax(clearance))
    return float(x[best]), float(y[best]), float(clearance[best])


#: Places of the test (tests/python/test_scene_cellophane.py), named: the strips over each.
PROBES = {
    "one layer at 45 deg": (0,),
    "two layers at 45 deg": (0, 1),
    "45 deg under -45 deg": (0, 3),
    "one layer at 60 deg": (4,),
    "60 deg under 15 deg": (4, 6),
    "two at 60 deg under -35 deg": (4, 5, 7),
}


def strips_as_shapes(bsdf: dict) -> dict:
    """Each strip as a rectangle of its own with `bsdf`, 1e-3 apart in height in laying order
    (the scene as one would build it with a plugin that takes no textures of thickness: the
    benchmark's `thindielectric` counterpart, bench/scenes.py)."""
    return {f"strip_{k}": {
        "type": "rectangle", "bsdf": bsdf,
        "to_world": T().translate([s.x, s.y, 1e-3 * k]).rotate([0, 0, 1], s.angle_deg)
        .scale([s.half_length, s.half_width, 1.0])} for k, s in enumerate(STRIPS)}


def scene(width: int = 360, height: int = 240, spp: int = 16, filter_bandwidth: float = 0.0,
          analyser_deg: float = 90.0, polarizer_deg: float = 0.0, thickness_um: float = THICKNESS_UM,
          index: float = INDEX, birefringence: float = BIREFRINGENCE,
          wavelength_nm: float | None = None) -> dict:
    """The scene as a dict for `mi.load_dict` (scalar_spectral_polarized).

    `polarizer_deg`, `analyser_deg`: transmission axes (counter-clockwise from x, seen from the
    camera); `wavelength_nm` makes the camera monochromatic (one channel, a 0.01 nm band).
    """
    return {
        "type": "scene",
        "integrator": {"type": "volpath", "max_depth": 8},
        "sensor": ortho_sensor(width, height, spp, VIEW_X, VIEW_Y, wavelength_nm=wavelength_nm),
        "light": backlight(-3.0, 4.0, black=True),
        # Mitsuba's polarizer transmits along -theta (see scenes/_common.py).
        "polarizer": layer(-1.0, 2 * VIEW_X, 2 * VIEW_Y, {"type": "polarizer", "theta": -polarizer_deg}),
        "cellophane": layer(0.0, VIEW_X, VIEW_Y, stack(filter_bandwidth, thickness_um=thickness_um,
                                                        index=index, birefringence=birefringence)),
        "analyser": layer(1.0, 2 * VIEW_X, 2 * VIEW_Y, {"type": "polarizer", "theta": -analyser_deg}),
    }


#: Gallery options (scenes/gallery.py): a channel render (`render_analytic`), no colour noise.
GALLERY = {"analytic": True, "spp": 16}
