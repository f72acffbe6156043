"""The overhead benchmark (bench/scenes.py, part 2) times what it says it does: the two rooms of
each pair are the same scene (sensor, film, sampler, spp, integrator, walls, light, shapes,
transforms, polarisers) and differ only in the BSDF under test, which is the plugin the row
names, of the kind it is labelled with (isotropic or anisotropic as the plugin itself reports
it), against the Mitsuba plugin a user would use instead; both rooms load in each variant
the pair is timed in; the channel-pass rooms are the pass render_analytic renders; and each row
is judged by the goal of its kind. The cellophane row is a whole scene, not a room: its two
scenes share everything but the film (one stack, or a `thindielectric` rectangle per strip).
Only scene descriptions are built and loaded here; nothing is rendered.
"""

import importlib.util
import pathlib
import warnings

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


WHOLE = {k for k, p in PAIRS.items() if p.ours.split("/")[0] in B.WHOLE_SCENES}
CASES = [(key, variant) for key, p in PAIRS.items() if key not in WHOLE for variant in p.variants]


@pytest.mark.parametrize("key,variant", CASES, ids=[f"{k}-{v}" for k, v in CASES])
def test_pair_differs_only_in_the_bsdf(key, variant):
    p = PAIRS[key]
    mi = B.set_variant(variant)
    ours_scene = B.overhead_room(mi, p.ours, variant)
    theirs_scene = B.overhead_room(mi, p.theirs, variant)
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


@pytest.mark.parametrize("key", [k for k, p in PAIRS.items() if "crossed polarisers" in p.what
                                 and k not in WHOLE])
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


@pytest.mark.parametrize("variant", list(B.CHANNEL_PASS))
def test_channel_pass_rooms_are_the_pass_render_analytic_renders(variant, monkeypatch):
    """The channel-pass room is the scene render_analytic loads for its channel (captured from a
    call of it), and it is a rewritten channel scene: our plates carry the channel, the film is
    one-channel, the emitter's D65 is the channel's white."""
    import mitsuba_birefringent
    from mitsuba_birefringent import analytic

    mi = B.set_variant(variant)
    key = "anisotropic/quartz_plates_50um"
    room = B.room(mi, B.CONFIGS[B.OVERHEAD_PAIRS[key].ours](mi))
    loaded = []
    monkeypatch.setattr(analytic, "render_pass", lambda d, spp, seed, quiet=False: loaded.append(d) or {})
    monkeypatch.setattr(analytic, "assemble", lambda images, to_srgb: None)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # it warns of the three plates (side by side here: exact)
        mitsuba_birefringent.render_analytic(room, spp=1)
    weights, channel = B.CHANNEL_PASS[variant].split(":")
    assert analytic.VARIANT == variant
    expected = loaded[analytic.CHANNELS[weights].index(channel)]
    ours = B.overhead_room(mi, B.OVERHEAD_PAIRS[key].ours, variant)
    assert plain(ours) == plain(expected)
    _, plates = split(ours)
    assert {b["channel"] for b in plates} == {B.CHANNEL_PASS[variant]}
    assert ours["sensor"]["film"]["pixel_format"] == "luminance"
    assert ours["lamp"]["emitter"]["radiance"]["type"] == "uniform"


def test_goals_per_row_kind():
    """The issue's goals: isotropic <= 1.3; birefringent plates <= 4 in the rgb variants, <= 2 in
    the spectral polarized ones, <= 3 for a channel pass; bulk crystals <= 2."""
    expected = {("anisotropic/quartz_plates_50um", "scalar_rgb"): 4.0,
                ("anisotropic/quartz_plates_50um", "llvm_ad_rgb"): 4.0,
                ("anisotropic/quartz_plates_50um", "scalar_spectral_polarized"): 2.0,
                ("anisotropic/photoelastic_plates_3mm", "llvm_ad_spectral_polarized"): 2.0,
                ("anisotropic/quartz_plates_50um", "llvm_ad_mono_polarized"): 3.0,
                ("anisotropic/calcite_solids", "llvm_ad_spectral_polarized"): 2.0,
                ("anisotropic/bouncing_calcite_sphere", "scalar_spectral_polarized"): 2.0,
                ("isotropic/bouncing_glass_sphere", "llvm_ad_rgb"): 1.3,
                ("isotropic/glass_panes", "scalar_spectral_polarized"): 1.3}
    for (key, variant), bound in expected.items():
        p = B.OVERHEAD_PAIRS[key]
        assert variant in p.variants
        assert B.OVERHEAD_GOALS[B.overhead_goal(p, variant)][1] == bound


def test_llvm_and_bouncing_rows_are_timed():
    """Every row of the scalar variants is also timed in its llvm counterpart; the quartz plates
    also as a channel pass; the bouncing crystals in both polarised variants."""
    for p in B.OVERHEAD_PAIRS.values():
        for scalar, llvm in (("scalar_rgb", "llvm_ad_rgb"),
                             ("scalar_spectral_polarized", "llvm_ad_spectral_polarized")):
            assert (scalar in p.variants) == (llvm in p.variants)
    for d in B.QUARTZ_UM:
        assert set(B.CHANNEL_PASS) <= set(B.OVERHEAD_PAIRS[f"anisotropic/quartz_plates_{d}um"].variants)
    calcite = B.OVERHEAD_PAIRS["anisotropic/bouncing_calcite_sphere"]
    assert set(calcite.variants) == {"scalar_spectral_polarized", "llvm_ad_spectral_polarized"}


@pytest.mark.parametrize("variant", B.OVERHEAD_PAIRS["anisotropic/cellophane"].variants)
def test_cellophane_pair_differs_only_in_the_film(variant):
    """Ours: the scene with its one stack; theirs: the same scene with one `thindielectric`
    rectangle per strip of the film's index instead; everything else equal."""
    p = B.OVERHEAD_PAIRS["anisotropic/cellophane"]
    assert WHOLE == {"anisotropic/cellophane"}
    mi = B.set_variant(variant)
    ours = plain(B.overhead_room(mi, p.ours, variant))
    theirs = plain(B.overhead_room(mi, p.theirs, variant))
    import cellophane  # scenes/ is on the path once a cellophane configuration was built

    stack = ours.pop("cellophane")["bsdf"]
    strips = {k: theirs.pop(k) for k in list(theirs) if k.startswith("strip_")}
    assert ours == theirs
    assert stack["type"] == p.plugin == "birefringentstack"
    assert len(strips) == len(cellophane.STRIPS)
    assert {s["bsdf"]["type"] for s in strips.values()} == {"thindielectric"}
    assert {s["bsdf"]["int_ior"] for s in strips.values()} == {cellophane.INDEX}
    assert bool(mi.load_dict(B.overhead_room(mi, p.ours, variant)["cellophane"]["bsdf"]).flags()
                & mi.BSDFFlags.Anisotropic)
    mi.load_dict(B.overhead_room(mi, p.theirs, variant))
