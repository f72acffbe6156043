"""The plugins' host path in the llvm variants (a plate or stack over a band or colour channels:
the core queried lane by lane from a wavefront, in evaluated mode) answers a batch of lanes
exactly as the scalar variant of the same spectrum type answers each lane alone (the kernel
path, the recorded programs, is compared lane for lane within float precision by
test_jit_recorded.py): random directions on both sides, both transport
modes, random lobe numbers and wavelengths, textures evaluated per lane (a checkerboard of
thicknesses, birefringence and axis angles), an optic axis in world space, the sampled lobes and
eval_null_transmission. Compared bit for bit (float32 outputs): both go through the same core
queries (tests/batch.rs: each lane of a batch is the scalar query) and the same conversions.

Also: the mono variants' plate is the luminance of the RGB plate (CIE Y = 0.2126 R + 0.7152 G +
0.0722 B of the linear sRGB channels, the colorimetric definition), and a batch gives the same
answers bit for bit whatever the size of Dr.Jit's thread pool (the core runs in chunks on it).
"""

from __future__ import annotations

import drjit as dr
import mitsuba as mi
import numpy as np
import pytest

from jit_helpers import LLVM, batch_si, context, evaluated_mode, random_directions, sample
from jit_helpers import scalar_counterpart

LANES = 600
#: Fewer in llvm_ad_rgb: its closed-form sRGB integration of a plate costs milliseconds a query.
RGB_LANES = 150
def CHECKER(a: float, b: float) -> dict:
    """A 3 x 3 checkerboard (built in the current variant)."""
    return {"type": "checkerboard", "color0": a, "color1": b,
            "to_uv": mi.ScalarTransform4f().scale([3, 3, 1])}


def plate(polarized: bool, exit_ior: float = 1.33) -> dict:
    """A quartz plate whose thickness, birefringence and axis angle vary over the surface
    (built in the current variant); with exit_ior 1 (= ext_ior) its transmission is a Null
    lobe."""
    return {"type": "thinbirefringent", "material": "quartz", "optic_axis": [1, 0.3, 0.2],
            "thickness": CHECKER(3.0, 17.0), "birefringence": CHECKER(0.0, 0.004),
            "axis_angle": CHECKER(10.0, 70.0), "filter_bandwidth": 4.0, "ext_ior": 1.0,
            "exit_ior": exit_ior}


def stack(polarized: bool) -> dict:
    """A stack of a quartz plate and two tapes, each textured over the surface (a checkerboard of
    thicknesses, axis angles and an added birefringence)."""
    tape = {"type": "thinbirefringent", "eta_o": 1.47, "eta_e": 1.478}
    return {"type": "birefringentstack", "ext_ior": 1.0, "exit_ior": 1.2, "filter_bandwidth": 4.0,
            "quartz": {"type": "thinbirefringent", "material": "quartz", "thickness": 12.0,
                       "axis_angle": CHECKER(0.0, 60.0)},
            "tape_1": dict(tape, thickness=CHECKER(20.0, 40.0), birefringence=CHECKER(0.0, 0.002)),
            "tape_2": dict(tape, thickness=35.0, axis_angle=CHECKER(30.0, 100.0))}


def inputs(seed: int, lanes: int = LANES):
    rng = np.random.default_rng(seed)
    wi = random_directions(lanes, rng)
    uv = rng.uniform(size=(lanes, 2)).astype(np.float32)
    waves = rng.uniform(380.0, 760.0, size=(lanes, 4)).astype(np.float32)
    u = rng.uniform(size=lanes).astype(np.float32)
    return wi, uv, waves, u


def scalar_answers(variant: str, make, mode: str, wi, uv, waves, u, null: bool):
    """Lane by lane in the scalar variant: (wo, pdf, eta, component, type, weight)."""
    mi.set_variant(variant)
    bsdf = mi.load_dict(make())
    ctx = context(mode)
    rows = []
    for i in range(len(wi)):
        si = mi.SurfaceInteraction3f()
        si.n = mi.Normal3f(0, 0, 1)
        si.sh_frame = mi.Frame3f(si.n)
        si.wi = mi.Vector3f(*[float(x) for x in wi[i]])
        si.uv = mi.Point2f(float(uv[i, 0]), float(uv[i, 1]))
        if mi.is_spectral:
            si.wavelengths = mi.UnpolarizedSpectrum(*[float(x) for x in waves[i]])
        if null:
            rows.append((None, np.array(bsdf.eval_null_transmission(si), dtype=np.float32)))
            continue
        bs, w = bsdf.sample(ctx, si, float(u[i]), mi.Point2f(0.5, 0.5))
        rows.append(((np.array(bs.wo, dtype=np.float32), float(bs.pdf), float(bs.eta),
                      int(bs.sampled_component), int(bs.sampled_type)),
                     np.array(w, dtype=np.float32)))
    return rows


@pytest.mark.parametrize("variant", [v for v in LLVM if scalar_counterpart(v)])
@pytest.mark.parametrize("kind", ["plate", "null", "stack"])
def test_llvm_batch_equals_scalar_lanes_bit_for_bit(variant, kind):
    polarized = "polarized" in variant
    makers = {"plate": lambda: plate(polarized), "null": lambda: plate(polarized, exit_ior=1.0),
              "stack": lambda: stack(polarized)}
    make = makers[kind]
    lanes = RGB_LANES if variant == "llvm_ad_rgb" else LANES
    wi, uv, waves, u = inputs(seed=len(variant) * 7 + len(kind), lanes=lanes)
    for mode in ("radiance", "importance") if kind != "null" else ("radiance",):
        mi.set_variant(variant)
        bsdf = mi.load_dict(make())
        si = batch_si(wi, waves, uv)
        if kind == "null":
            with evaluated_mode():
                w = np.array(bsdf.eval_null_transmission(si), dtype=np.float32)
        else:
            out, w = sample(bsdf, context(mode), si, u)
        rows = scalar_answers(scalar_counterpart(variant), make, mode, wi, uv, waves, u,
                              kind == "null")
        sampled = 0
        for i, (fields, ws) in enumerate(rows):
            lane = w[..., i]
            assert np.array_equal(lane, ws.reshape(lane.shape)), (mode, i, lane, ws)
            if fields is None:
                continue
            wo, pdf, eta, comp, typ = fields
            assert np.array_equal(out["wo"][i], wo), (mode, i)
            assert (out["pdf"][i], out["eta"][i]) == (np.float32(pdf), np.float32(eta)), (mode, i)
            assert (out["component"][i], out["type"][i]) == (comp, typ), (mode, i)
            sampled += pdf > 0
        if kind != "null":
            assert sampled > 0.5 * lanes, sampled
    print(f"{variant} {kind}: {lanes} lanes per mode equal bit for bit")


def test_mono_plate_is_the_luminance_of_the_rgb_plate():
    """llvm_ad_mono's plate value = 0.2126 R + 0.7152 G + 0.0722 B of llvm_ad_rgb's, lane by
    lane (the two closed forms integrate separate Gaussian fits of the CIE tables: Y and the
    sRGB weights; measured worst 2e-4, bound 1e-3 of values up to 1)."""
    wi, uv, waves, u = inputs(seed=5, lanes=RGB_LANES)
    values = {}
    for v in ("llvm_ad_mono", "llvm_ad_rgb"):
        mi.set_variant(v)
        bsdf = mi.load_dict(plate(False))
        out, w = sample(bsdf, context("radiance", 1), batch_si(wi, None, uv), u)
        values[v] = w * out["pdf"]
    y = np.array([0.2126, 0.7152, 0.0722]) @ values["llvm_ad_rgb"]
    worst = float(np.abs(values["llvm_ad_mono"][0] - y).max())
    print(f"mono vs luminance of rgb: worst {worst:.2e} (values up to {y.max():.3f})")
    assert worst < 1e-3 and y.max() > 0.5


def test_batch_is_the_same_with_one_and_two_threads():
    """40,000 lanes (10 chunks of the core on Dr.Jit's pool; plates over a 4 nm band, the
    host query): the answers do not depend on how many threads run the chunks, bit for bit."""
    mi.set_variant("llvm_ad_spectral_polarized")
    rng = np.random.default_rng(11)
    n = 40_000
    wi = random_directions(n, rng)
    waves = rng.uniform(380.0, 760.0, size=(n, 4)).astype(np.float32)
    uv = rng.uniform(size=(n, 2)).astype(np.float32)
    u = rng.uniform(size=n).astype(np.float32)
    results = []
    threads = dr.thread_count()
    try:
        for count in (1, 2):
            dr.set_thread_count(count)
            for d in (plate(True), plate(True, exit_ior=1.0)):
                out, w = sample(mi.load_dict(d), context("radiance"), batch_si(wi, waves, uv), u)
                results.append((count, w, out["wo"], out["pdf"]))
    finally:
        dr.set_thread_count(threads)
    for (c1, *a), (c2, *b) in zip(results[:2], results[2:]):
        for x, y in zip(a, b):
            assert np.array_equal(x, y)
