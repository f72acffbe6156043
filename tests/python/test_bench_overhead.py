"""The overhead benchmark (bench/scenes.py, part 2) times what it says it does: the two rooms of
each pair are the same scene (sensor, film, sampler, spp, integrator, walls, light, shapes,
transforms, polarisers) and differ only in the BSDF under test, which is the plugin the row
names, of the kind it is labelled with (isotropic or anisotropic as the plugin itself reports
it), against the Mitsuba plugin a user would use instead; and both rooms load in each variant
the pair is timed in. Only scene descriptions are built and loaded here; nothing is rendered.
"""

import importlib.util
import pathlib

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


def bench_scenes():
    spec = importlib.util.spec_from_file_location("bench_scenes", ROOT / "bench" / "scenes.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


B = bench_scenes()
PAIRS = {**B.OVERHEAD_PAIRS, **B.FAST_PATH_PAIRS}
#: The BSDFs a pair may differ in (ours and Mitsuba's); every other entry must be equal.
UNDER_TEST = ("thinbirefringent", "birefringent", "thindielectric", "dielectric")
#: The Mitsuba plugin a user would take instead of ours.
MITSUBA_COUNTERPART = {"thinbirefringent": "thindielectric", "birefringent": "dielectric"}
PLACEHOLDER = "<bsdf under test>"


def plain(value):
    """`value` with Mitsuba transforms as nested lists of their matrices (comparable with ==)."""
    if isinstance(value, dict):
        return {k: plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    if hasattr(value, "matrix"):
        return np.array(value.matrix).tolist()
    return value


def split(scene: dict) -> tuple[dict, list[dict]]:
    """The scene with every BSDF of UNDER_TEST replaced by a placeholder, and those BSDFs."""
    found = []

    def walk(d: dict) -> dict:
        out = {}
        for k, v in d.items():
            if k == "bsdf" and isinstance(v, dict) and v.get("type") in UNDER_TEST:
                found.append(v)
                out[k] = PLACEHOLDER
            else:
                out[k] = walk(v) if isinstance(v, dict) else v
        return out

    return walk(plain(scene)), found


CASES = [(key, variant) for key, p in PAIRS.items() for variant in p.variants]


@pytest.mark.parametrize("key,variant", CASES, ids=[f"{k}-{v}" for k, v in CASES])
def test_pair_differs_only_in_the_bsdf(key, variant):
    p = PAIRS[key]
    mi = B.set_variant(variant)
    ours_scene = B.room(mi, B.CONFIGS[p.ours](mi))
    theirs_scene = B.room(mi, B.CONFIGS[p.theirs](mi))
    ours_rest, ours = split(ours_scene)
    theirs_rest, theirs = split(theirs_scene)
    assert ours_rest == theirs_rest
    assert ours and len(ours) == len(theirs)
    # one BSDF under test per room, the same on every object
    assert all(b == ours[0] for b in ours) and all(b == theirs[0] for b in theirs)
    assert ours[0]["type"] == p.plugin
    anisotropic = lambda bsdf: bool(mi.load_dict(bsdf).flags() & mi.BSDFFlags.Anisotropic)  # noqa: E731
    assert anisotropic(ours[0]) == (p.kind == "anisotropic")
    if key in B.OVERHEAD_PAIRS:
        assert theirs[0]["type"] == MITSUBA_COUNTERPART[p.plugin]
    else:  # the isotropic fast path: ours, birefringent to the core, against ours isotropic
        assert theirs[0]["type"] == p.plugin and not anisotropic(theirs[0])
    mi.load_dict(ours_scene)
    mi.load_dict(theirs_scene)


@pytest.mark.parametrize("key", [k for k, p in PAIRS.items() if "crossed polarisers" in p.what])
def test_plates_stand_between_crossed_polarizers(key):
    mi = B.set_variant("scalar_spectral_polarized")
    rest, plates = split(B.room(mi, B.CONFIGS[PAIRS[key].ours](mi)))
    bsdfs = [v["bsdf"] for v in rest.values() if isinstance(v, dict) and "bsdf" in v]
    thetas = [b["theta"] for b in bsdfs if b != PLACEHOLDER and b["type"] == "polarizer"]
    assert len(thetas) == 2 * len(plates)
    assert sorted(thetas) == [-45.0] * len(plates) + [45.0] * len(plates)


def test_quartz_rows_have_their_thicknesses():
    """Each quartz row's plate is as thick as its name says (the configurations are made in a
    loop; a late-bound loop variable would give all of them the last thickness)."""
    mi = B.set_variant("scalar_rgb")
    for d in B.QUARTZ_UM:
        p = B.OVERHEAD_PAIRS[f"anisotropic/quartz_plates_{d}um"]
        _, plates = split(B.room(mi, B.CONFIGS[p.ours](mi)))
        assert {b["thickness"] for b in plates} == {float(d)}
        assert {b["material"] for b in plates} == {"quartz"}
