"""Wavefronts of several chunks in every llvm variant: an instance's lanes beyond the first
chunk (the shim sends the core ChunkLanes = 1024 lanes per call, cpp/src/bridge.h) get the
answers each lane gets alone. test_jit_batch.py compares smaller batches (one chunk); here one
call of a BSDF pointer array reaches four instances, as a wavefront reaches a scene's BSDFs
(Mitsuba hands each instance its own lanes, compacted: their order and count differ from the
wavefront's). The lanes mix directions on both sides, lobe numbers, wavelengths and materials:
a textured plate of constant indices and a sapphire plate on an absorbing exit, ~1100 lanes
each, so two chunks each; a quartz plate and a calcite Null plate, fewer lanes (a channel integration of a dispersive crystal
costs milliseconds a lane); in the mono variants each instance renders another channel of
another weight set (the passes of channel renders). These are the plugins' host queries (in the
spectral variants over a band of 4 nm: at exact wavelengths, and a crystal surface in every
JIT variant, they run inside the kernel, compared lane for lane by test_jit_recorded.py).

Each lane is compared bit for bit (float32 outputs: the same core queries and conversions) with
the same lane queried alone: in the scalar variant of the same spectrum type, or, for the mono
variants (the wheel has no scalar mono variant), as a one-lane call of the same variant (which
lies in the first chunk at index 0). Both the sampled lobes and eval_null_transmission (whose
frames are built from -wi) are checked. A lane-index slip in the shim (a chunk's lane read at
its index within the chunk, measured: 1976 of 3000 lanes wrong, |dM| up to 4.3) fails here.
"""

from __future__ import annotations

import drjit as dr
import mitsuba as mi
import numpy as np
import pytest

from jit_helpers import LLVM, batch_si, context, evaluated_mode, random_directions
from jit_helpers import scalar_counterpart

#: Lanes of the wavefront: the textured plate and the crystal get 45 % each (two chunks each:
#: 1024 and ~100 lanes).
LANES = 2500
#: Share of the wavefront per instance (in the order of `instances`).
SHARES = (0.45, 0.05, 0.05, 0.45)
#: Instances with two chunks.
LONG = (0, 3)
#: Lanes compared with their lone query (a lone query costs ~3 ms in an llvm variant, up to
#: milliseconds in scalar_rgb): in each instance of LONG the last 10 lanes of its first chunk and
#: the first 10 of its second, CHECKED others of the second chunks, CHECKED others at random.
CHECKED = 100
#: The channel of each instance in the mono variants.
CHANNELS = ("srgb-d65:R", "xyz-e:Z", "xyz-d65:X", "srgb-d65:G")


def checker(a: float, b: float) -> dict:
    return {"type": "checkerboard", "color0": a, "color1": b,
            "to_uv": mi.ScalarTransform4f().scale([3, 3, 1])}


def instances(mono: bool) -> list[dict]:
    """The four BSDFs (dicts built in the current variant), with their channels in the mono
    variants."""
    spectral = {"filter_bandwidth": 4.0} if mi.is_spectral else {}
    out = [
        {"type": "thinbirefringent", "eta_o": 1.5, "eta_e": 1.56, "optic_axis": [1, 0.3, 0.2],
         "thickness": checker(0.3, 0.9), "birefringence": checker(0.0, 0.004),
         "axis_angle": checker(10.0, 70.0), "ext_ior": 1.0, "exit_ior": 1.33, **spectral},
        {"type": "thinbirefringent", "material": "quartz", "optic_axis": [0.2, 1, 0.5],
         "thickness": 2.0, "axis_angle": 25.0, "ext_ior": 1.2, "exit_ior": 1.0, **spectral},
        {"type": "thinbirefringent", "material": "calcite", "optic_axis": [0, 0.4, 1],
         "thickness": 0.5, "ext_ior": 1.0, "exit_ior": 1.0, **spectral},
        {"type": "thinbirefringent", "material": "sapphire", "optic_axis": [0.3, 0.5, 0.8],
         "thickness": 1.5, "ext_ior": 1.0, "absorbing_exit": True, **spectral},
    ]
    if mono:
        out = [{**d, "channel": c} for d, c in zip(out, CHANNELS)]
    return out


def wavefront(seed: int, n: int):
    rng = np.random.default_rng(seed)
    which = rng.choice(len(SHARES), size=n, p=SHARES).astype(np.uint32)
    wi = random_directions(n, rng)
    uv = rng.uniform(size=(n, 2)).astype(np.float32)
    waves = rng.uniform(380.0, 760.0, size=(n, 4)).astype(np.float32)
    u = rng.uniform(size=n).astype(np.float32)
    position = np.zeros(n, dtype=np.int64)  # each lane's index among its instance's lanes
    for k in range(len(SHARES)):
        position[which == k] = np.arange(np.count_nonzero(which == k))
    edge = np.flatnonzero(np.isin(which, LONG) & (np.abs(position - 1024 + 0.5) < 10))
    late = np.flatnonzero(np.isin(which, LONG) & (position >= 1024 + 10))
    late = np.concatenate([edge, rng.choice(late, size=min(CHECKED, len(late)), replace=False)])
    others = rng.choice(np.setdiff1d(np.arange(n), late), size=CHECKED, replace=False)
    return which, wi, uv, waves, u, position, np.sort(np.concatenate([late, others]))


def batch_answers(bsdfs, which, wi, uv, waves, u, mode: str):
    """One call of the pointer array over every lane: (wo, pdf, eta, component, type, weight,
    null transmission), numpy, lanes last (wo: lanes x 3)."""
    n = len(u)
    ptrs = dr.gather(mi.BSDFPtr, mi.BSDFPtr(bsdfs), mi.UInt32(which))
    si = batch_si(wi, waves, uv)
    lanes = lambda x: np.broadcast_to(np.array(x), np.array(x).shape[:-1] + (n,))  # noqa: E731
    with evaluated_mode():
        bs, w = ptrs.sample(context(mode), si, mi.Float(u), mi.Point2f(0.5, 0.5), True)
        null = ptrs.eval_null_transmission(si, True)
        return (lanes(bs.wo).T, lanes(bs.pdf), lanes(bs.eta), lanes(bs.sampled_component),
                lanes(bs.sampled_type), lanes(w), lanes(null))


def alone(bsdf, wi, uv, waves, u, mode: str):
    """The same outputs for one lane queried alone with `bsdf` (a BSDF of the current variant:
    scalar, or a one-lane call of an llvm variant)."""
    if dr.is_jit_v(mi.Float):
        out = batch_answers([bsdf], np.zeros(1, np.uint32), wi[None], uv[None], waves[None],
                            np.array([u]), mode)
        return tuple(x[..., 0] if k != 0 else x[0] for k, x in enumerate(out))
    si = mi.SurfaceInteraction3f()
    si.n = mi.Normal3f(0, 0, 1)
    si.sh_frame = mi.Frame3f(si.n)
    si.wi = mi.Vector3f(*[float(x) for x in wi])
    si.uv = mi.Point2f(float(uv[0]), float(uv[1]))
    if mi.is_spectral:
        si.wavelengths = mi.UnpolarizedSpectrum(*[float(x) for x in waves])
    bs, w = bsdf.sample(context(mode), si, float(u), mi.Point2f(0.5, 0.5))
    return (np.array(bs.wo), np.float32(bs.pdf), np.float32(bs.eta), int(bs.sampled_component),
            int(bs.sampled_type), np.array(w), np.array(bsdf.eval_null_transmission(si)))


@pytest.mark.parametrize("variant", LLVM)
def test_every_lane_of_a_many_chunk_wavefront_is_its_lone_query(variant):
    mono = "mono" in variant
    which, wi, uv, waves, u, position, checked = wavefront(seed=len(variant) * 13, n=LANES)
    mode = "importance" if "polarized" in variant else "radiance"
    mi.set_variant(variant)
    out = batch_answers([mi.load_dict(d) for d in instances(mono)], which, wi, uv, waves, u, mode)
    mi.set_variant(scalar_counterpart(variant) or variant)
    lone = [mi.load_dict(d) for d in instances(mono)]
    beyond = 0  # checked lanes past the first chunk of their instance
    names = ("wo", "pdf", "eta", "component", "type", "weight", "null")
    for i in checked:
        want = alone(lone[which[i]], wi[i], uv[i], waves[i], u[i], mode)
        for name, got, w in zip(names, (x[..., i] if k else x[i] for k, x in enumerate(out)), want):
            w = np.asarray(w, dtype=np.float32)
            assert np.array_equal(np.asarray(got, np.float32).ravel(), w.ravel()), (
                f"lane {i} (instance {which[i]}, its lane {position[i]}): {name} {got} != {w}")
        beyond += position[i] >= 1024
    sampled = np.count_nonzero(out[1] > 0)
    print(f"{variant}: {LANES} lanes, {len(checked)} checked alone ({beyond} beyond an instance's "
          f"first chunk), {sampled} sampled a lobe")
    assert all(np.count_nonzero(which == k) > 1024 + 50 for k in LONG)
    assert beyond > 100 and sampled > LANES / 2
