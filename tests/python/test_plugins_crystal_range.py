"""Named crystals over the wavelengths Mitsuba's spectral variants sample (360-830 nm).

Two crystals' cited data stop short of 360 nm (rutile: DeVore 1951, 430-1530 nm; lithium niobate:
Zelmon et al. 1997, 400-5000 nm). The rule (the core's `Material::coverage`, the same one the
calculator applies, tests/crystal_range.rs): their fits are extrapolated down to 360 nm, and
loading such a crystal logs one warning that states the data's range; nothing else warns, and
every wavelength gives finite lobes.
"""

from __future__ import annotations

import numpy as np
import pytest

import mitsuba as mi

from bfr_helpers import POLARIZED, context, direction, sample, surface_interaction, variant

# (name, first nm of its data): the catalogue's ranges, src/material/crystals.rs
SHORT = {"rutile": 430, "linbo3": 400}
NAMES = ["calcite", "quartz", "sapphire", "rutile", "mgf2", "linbo3", "bbo", "kdp"]


class Recorder(mi.Appender):
    """Keeps every log message at Warn or above."""

    def __init__(self):
        super().__init__()
        self.warnings = []

    def append(self, level, text):
        if level >= mi.LogLevel.Warn:
            self.warnings.append(text)

    def log_progress(self, *args):
        pass


@pytest.fixture
def log():
    rec = Recorder()
    mi.logger().add_appender(rec)
    yield rec
    mi.logger().remove_appender(rec)


def grid_batches():
    grid = np.arange(360.0, 831.0)
    grid = np.concatenate([grid, np.full((-len(grid)) % 4, grid[-1])])
    return grid.reshape(-1, 4)


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("kind", ["thinbirefringent", "birefringent"])
def test_every_crystal_loads_with_the_documented_warning_and_gives_finite_lobes(log, kind, name):
    """Each crystal, both plugins, every nm from 360 to 830 (both modes, both components of the
    plate; the bulk surface's sampled lobe): finite weights, and one warning at load exactly
    for the crystals whose data do not reach 360 nm, naming the data's first wavelength."""
    variant(POLARIZED)
    params = {"type": kind, "material": name, "optic_axis": [0.3, 0.2, 0.9]}
    if kind == "thinbirefringent":
        params["thickness"] = 2.0
    else:
        params["optic_axis_space"] = "local"
    bsdf = mi.load_dict(params)
    loaded = list(log.warnings)
    if name in SHORT:
        assert len(loaded) == 1, loaded
        assert f"cover {SHORT[name]}-" in loaded[0] and f"360-{SHORT[name]} nm" in loaded[0]
    else:
        assert loaded == []
    wi = direction(30, 20)
    for wl in grid_batches():
        si = surface_interaction(wi, wavelengths=wl)
        for mode in ("radiance", "importance"):
            for component in ((0, 1) if kind == "thinbirefringent" else (None,)):
                bs, w = sample(bsdf, context(mode, component), si, 0.3)
                assert float(bs.pdf) > 0 and np.all(np.isfinite(w)), (name, wl, mode, component)
                assert w[0, 0].min() >= 0
    assert log.warnings == loaded  # nothing warns while sampling


def test_rutile_plate_renders_with_one_load_warning(log):
    """A rutile plate (5 um, optic axis in its plane) on a diffuse floor under a white light,
    scalar_spectral_polarized: the load warning and nothing else; a finite, non-black image."""
    variant(POLARIZED)
    T = mi.ScalarTransform4f
    scene = mi.load_dict({
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 4},
        "sensor": {"type": "perspective", "fov": 40,
                   "to_world": T().look_at(origin=[0, -2, 2], target=[0, 0, 0], up=[0, 0, 1]),
                   "film": {"type": "hdrfilm", "width": 16, "height": 16,
                            "rfilter": {"type": "box"}},
                   "sampler": {"type": "independent", "sample_count": 8}},
        "light": {"type": "constant", "radiance": {"type": "d65"}},
        "floor": {"type": "rectangle", "to_world": T().scale(3),
                  "bsdf": {"type": "diffuse", "reflectance": 0.5}},
        "plate": {"type": "rectangle", "to_world": T().translate([0, 0, 0.5]),
                  "bsdf": {"type": "thinbirefringent", "material": "rutile", "thickness": 5.0,
                           "optic_axis": [1, 0, 0]}},
    })
    assert len(log.warnings) == 1 and "rutile cover 430-1530 nm" in log.warnings[0]
    img = np.array(mi.render(scene, seed=1))
    assert len(log.warnings) == 1, log.warnings
    assert np.all(np.isfinite(img)) and img[..., :3].mean() > 0.05
