"""scenes/michel_levy.py (in the gallery): a quartz wedge between polarisers. At zero
thickness (left edge) crossed polarisers extinguish the light and parallel ones pass it; where
the retardation is half a wave for green light the crossed image is at its brightest for green;
crossed + parallel = the plate's unpolarised transmission between polarisers, i.e. the light
through one polariser (the wedge is lossless up to reflections)."""

import pathlib
import sys

import mitsuba as mi
import numpy as np

import mitsuba_birefringent  # noqa: F401

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "scenes"))
import michel_levy  # noqa: E402


def render(crossed: bool) -> np.ndarray:
    mi.set_variant("scalar_spectral_polarized")
    scene = mi.load_dict(michel_levy.scene(width=48, height=4, spp=64, crossed=crossed))
    return np.array(mi.render(scene, seed=1))


def test_wedge_between_polarisers():
    crossed, parallel = render(True), render(False)
    lum = lambda img: img[..., :3].mean(axis=(0, 2))  # per column
    c, p = lum(crossed), lum(parallel)
    # Left edge: thickness ~0 -> extinction between crossed polarisers.
    assert c[0] < 0.05 * p[0], (c[0], p[0])
    # Crossed + parallel is independent of the retardation (Malus): flat along the wedge
    # within the Monte Carlo noise of 64 spp and the plate's reflection fringes.
    total = c + p
    assert np.std(total) < 0.08 * np.mean(total), total
    # Somewhere along the wedge the crossed image is brighter than the parallel one.
    assert (c > p).any()
