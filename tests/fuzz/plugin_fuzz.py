"""Fuzzer of the plugin parameters: random and hostile `thinbirefringent` / `birefringent`
dictionaries through `mi.load_dict` in every supported variant, each case in a worker
SUBPROCESS so that a segfault or an abort in the shim, the core or Mitsuba is seen (and the
input kept) instead of killing the fuzzer.

    .venv/bin/python tests/fuzz/plugin_fuzz.py --seconds 30 [--seed 1] [--out target/fuzz/plugin]

Contract of every case (a violation is a finding):
- `mi.load_dict` either returns a BSDF or raises a Python exception whose message is non-empty
  and names one of the dictionary's keys (a parameter, a nested texture's parameter, or the
  value of the offending string parameter), and the parameter it names first is one the
  dictionary gives (or one that a given one implies: `thickness` for `thickness_scale`), never
  a name the user did not write; never a crash;
- a loaded BSDF's `sample`, `eval`, `pdf` and `eval_null_transmission` on random surface
  interactions (random and grazing directions on both sides, random wavelengths and uv, both
  transport modes, random components) return finite numbers, a pdf >= 0 and a finite unit `wo`
  whenever the weight is non-zero;
- soft (listed; a failure with --strict, which `make test` uses): the core never answers a query
  with its internal error (a panic it caught, or a non-finite result it refused: the plugin then
  logs one warning, returns no light and the numbers above stay finite, so only the log shows
  it). The worker captures Mitsuba's log (warnings and errors, not printed) to see it.

Why not atheris: its coverage guidance instruments Python bytecode, while everything under
test here is native (the C++ shim, the Rust core, Mitsuba), built without libFuzzer's
instrumentation, so it would guide nothing; the native code is fuzzed with coverage by the
libFuzzer targets of tests/fuzz/ (the C ABI the shim calls, fed the same hostile values). This
is a seeded random generator of hostile dictionaries: case i of seed s is always the same
dictionary (`--case` replays one).

A case that runs longer than SLOW seconds is listed as slow (single sRGB-integrated or
band-filtered plate queries can take seconds: reported to the lead); one running past --hang is
a hang (a finding). (Extreme magnitudes that once crashed the renderer or handed it inf are
now refused by the core at load, with a message naming the parameter.)

Exit status 0 if no case crashed, hung or broke the contract (with --strict: nor broke the soft
contract), 1 otherwise (the cases are written to --out as JSON, with a command to replay each).
"""

from __future__ import annotations

import argparse
import json
import math
import queue
import random
import subprocess
import sys
import threading
import time
from pathlib import Path

VARIANTS = ("scalar_rgb", "scalar_spectral", "scalar_spectral_polarized")
PLUGINS = ("thinbirefringent", "birefringent")

HOSTILE = [math.nan, -math.nan, math.inf, -math.inf, 0.0, -0.0, 5e-324, 2.2e-308, 1e-300,
           1e-12, 1e-8, 1e-4, 0.5, 1.0, -1.0, 1.0001, 1.5, 1.55, 2.4, 4.0, 20.0, 1e8, 1e30,
           1e300, 1.7976931348623157e308, -1e300, 3.4028235e38, 3.5e38, -3.5e38]
NAMES = ["calcite", "quartz", "crystalline quartz", "sapphire", "rutile", "mgf2", "linbo3",
         "bbo", "kdp", "", " ", "CALCITE", "unobtainium", "calcite\u00e9", "x" * 5000]
IOR_NAMES = ["air", "water", "bk7", "vacuum", "diamond", "unobtainium", ""]


def hostile_float(r: random.Random) -> float:
    k = r.random()
    if k < 0.5:
        return r.choice(HOSTILE)
    if k < 0.8:
        return r.uniform(0.0, 5.0)
    return math.copysign(10.0 ** r.uniform(-320, 308), r.choice([-1, 1]))


def wrong_type(r: random.Random):
    return r.choice(["1.5", [1.0, 2.0], [], {"type": "nonexistent"}, True, 3, -7, [math.nan] * 3])


def colour(r: random.Random):
    """A number written as a colour: a grey or coloured rgb, a uniform or varying spectrum, an
    srgb texture (the plugins read a grey rgb and a uniform spectrum as the number and refuse
    the others, naming the parameter)."""
    x = hostile_float(r)
    k = r.randrange(5)
    if k == 0:
        return {"type": "rgb", "value": [x, x, x]}
    if k == 1:
        return {"type": "rgb", "value": [x, hostile_float(r), x]}
    if k == 2:
        return {"type": "spectrum", "value": x}
    if k == 3:
        return {"type": "spectrum", "value": [(400.0, x), (700.0, hostile_float(r))]}
    return {"type": "srgb", "color": [r.random(), r.random(), r.random()]}


def texture(r: random.Random):
    """A float, a colour, or a checkerboard whose two values may be hostile (render-time
    values)."""
    k = r.random()
    if k < 0.5:
        return hostile_float(r) if r.random() < 0.95 else wrong_type(r)
    if k < 0.65:
        return colour(r)
    return {"type": "checkerboard", "color0": hostile_float(r), "color1": hostile_float(r)}


def ior(r: random.Random):
    """An index: a float, an IOR name, or (wrongly) a colour."""
    k = r.random()
    if k < 0.6:
        return hostile_float(r)
    return r.choice(IOR_NAMES) if k < 0.9 else colour(r)


def axis(r: random.Random):
    k = r.random()
    if k < 0.5:
        return [hostile_float(r) for _ in range(3)]
    if k < 0.8:
        v = [r.gauss(0, 1) for _ in range(3)]
        return v
    return r.choice([[0, 0, 0], [1, 2], [1, 2, 3, 4], "up", [1e-30, 0, 0], [1e30, 1e30, 1e30]])


def case(seed: int, index: int) -> dict:
    """The dictionary of case `index` of `seed` (deterministic)."""
    r = random.Random(seed * 1_000_003 + index)
    kind = r.choice(PLUGINS)
    d: dict = {"type": kind}
    p = r.random
    if p() < 0.5:
        d["material"] = r.choice(NAMES) if p() < 0.9 else wrong_type(r)
    if p() < 0.4:
        d["eta_o"] = hostile_float(r) if p() < 0.9 else wrong_type(r)
    if p() < 0.4:
        d["eta_e"] = hostile_float(r) if p() < 0.9 else wrong_type(r)
    for key in ("kappa_o", "kappa_e"):
        if p() < 0.3:
            d[key] = hostile_float(r)
    if p() < 0.5:
        d["optic_axis"] = axis(r)
    if p() < 0.3:
        d["ext_ior"] = ior(r)
    if kind == "thinbirefringent":
        if p() < 0.6:
            d["thickness"] = texture(r)
        for key in ("thickness_scale", "birefringence_scale", "filter_bandwidth"):
            if p() < 0.25:
                d[key] = hostile_float(r)
        for key in ("birefringence", "axis_angle"):
            if p() < 0.25:
                d[key] = texture(r)
        if p() < 0.3:
            d["exit_ior"] = ior(r)
    else:
        if p() < 0.3:
            d["optic_axis_space"] = r.choice(["local", "world", "object", ""])
    if p() < 0.05:
        d["no_such_parameter"] = 1.0
    return d


# A case whose one query is slower than this (s) is listed as slow; the budget ends a slow case
# GRACE seconds after the deadline (listed, not a failure).
SLOW, GRACE = 10.0, 10.0


def numbers(v) -> list[float]:
    """The finite numbers of a parameter value (a float, or a texture's nested values)."""
    if isinstance(v, bool):
        return []
    if isinstance(v, (int, float)):
        return [float(v)] if math.isfinite(v) else []
    if isinstance(v, dict):
        return [x for w in v.values() for x in numbers(w)]
    return []


def keys_of(d) -> set[str]:
    """Every key and string value of a (nested) dictionary: one of them must be named by a
    load error."""
    out: set[str] = set()
    if isinstance(d, dict):
        for k, v in d.items():
            if k != "type":
                out.add(k)
            out |= keys_of(v)
    elif isinstance(d, str) and d:
        out.add(d[:60])
    return out


# What the core's internal error looks like in a message: `Error::new("internal", ...)` prints as
# "internal: ...", a caught panic as "internal error (panic caught)", and both say "a bug" or
# "internal error" (src/ffi.rs, src/calc/mod.rs).
INTERNAL_MARKERS = ("internal: ", "internal error", "a bug: please report")


def log_capture(mi):
    """Replaces the appenders of Mitsuba's logger by one that keeps every warning and error
    (a list of strings, returned) and prints nothing."""

    class Capture(mi.Appender):
        def __init__(self):
            super().__init__()
            self.messages: list[str] = []

        def append(self, level, text):
            self.messages.append(text)

        def log_progress(self, *args):
            pass

    capture = Capture()
    logger = mi.logger()
    logger.clear_appenders()
    logger.add_appender(capture)
    logger.set_log_level(mi.LogLevel.Warn)
    return capture


def internal_errors(messages) -> list[str]:
    return [m for m in messages if any(k in m for k in INTERNAL_MARKERS)]


# A message may name a parameter the dictionary does not give when that parameter's default
# is combined with one it does give (the plate's thickness is thickness x thickness_scale).
# eta_o and eta_e go together (the one missing is named).
IMPLIED_BY = {"thickness": {"thickness_scale"}, "birefringence": {"birefringence_scale"},
              "exit_ior": {"ext_ior"}, "eta_o": {"eta_e"}, "eta_e": {"eta_o"}}


def named_parameter(msg: str) -> str | None:
    """The parameter a load error names first: `NAME: ...` / `NAME[i]: ...` (the core) or
    `"NAME" ...` (the shim) after the plugin's tag, or Mitsuba's `property "NAME"`; None when
    the message starts otherwise (e.g. a rule about several parameters)."""
    import re

    tags = [msg.rfind(t) for t in ("[ThinBirefringent] ", "[Birefringent] ")]
    at = max(tags)
    if at >= 0:
        rest = msg[msg.index("] ", at) + 2:]
        m = re.match(r'"([a-z_]+)"\s|([a-z_]+)(\[\d+\])?:\s', rest)
        return (m.group(1) or m.group(2)) if m else None
    m = re.search(r'property "([^"]+)"', msg)
    return m.group(1) if m else None


def names_a_given_parameter(msg: str, d: dict) -> bool:
    """False when the message names a parameter that the dictionary does not give (and that
    nothing it gives implies), e.g. `optic_axis` for a non-finite `axis_angle`."""
    name = named_parameter(msg)
    if name is None:
        return True
    given = keys_of(d)
    return name in given or bool(IMPLIED_BY.get(name, set()) & given)


def queries(mi, dr, bsdf, r: random.Random, n: int) -> str | None:
    """Random queries of a loaded BSDF; the first broken contract, or None."""
    for _ in range(n):
        k = r.random()
        if k < 0.1:
            z = r.choice([0.0, 1e-7, -1e-7, 1.0, -1.0])
            a = r.uniform(0, 2 * math.pi)
            s = math.sqrt(max(0.0, 1 - z * z))
            wi = [s * math.cos(a), s * math.sin(a), z]
        else:
            v = [r.gauss(0, 1) for _ in range(3)]
            norm = math.sqrt(sum(x * x for x in v)) or 1.0
            wi = [x / norm for x in v]
        si = dr.zeros(mi.SurfaceInteraction3f)
        si.n = mi.Normal3f(0, 0, 1)
        si.sh_frame = mi.Frame3f(si.n)
        si.wi = mi.Vector3f(*wi)
        si.uv = mi.Point2f(r.random(), r.random())
        si.p = mi.Point3f(r.uniform(-1, 1), r.uniform(-1, 1), 0)
        if mi.is_spectral:
            si.wavelengths = mi.UnpolarizedSpectrum(*[r.uniform(360.0, 830.0) for _ in range(4)])
        mode = r.choice([mi.TransportMode.Radiance, mi.TransportMode.Importance])
        ctx = mi.BSDFContext(mode)
        if r.random() < 0.3:
            ctx.component = r.randrange(0, 3)
        bs, w = bsdf.sample(ctx, si, r.random(), mi.Point2f(r.random(), r.random()))
        w = [float(x) for x in dr.ravel(w)] if hasattr(dr, "ravel") else list(map(float, w))
        where = f"wi={wi}, mode={mode}, uv={list(si.uv)}"
        if not all(math.isfinite(x) for x in w):
            return f"sample weight not finite: {w} at {where}"
        pdf = float(bs.pdf)
        if not (math.isfinite(pdf) and pdf >= 0):
            return f"sample pdf {pdf} at {where}"
        if any(x != 0.0 for x in w):
            wo = [float(bs.wo.x), float(bs.wo.y), float(bs.wo.z)]
            if not all(math.isfinite(x) for x in wo) or abs(math.sqrt(sum(x * x for x in wo)) - 1) > 1e-4:
                return f"sample wo {wo} at {where}"
            if not math.isfinite(float(bs.eta)):
                return f"sample eta {bs.eta} at {where}"
        wo = mi.Vector3f(*[-x for x in wi])
        e = [float(x) for x in dr.ravel(bsdf.eval(ctx, si, wo))]
        t = [float(x) for x in dr.ravel(bsdf.eval_null_transmission(si))]
        pe = float(bsdf.pdf(ctx, si, wo))
        if not all(math.isfinite(x) for x in e + t + [pe]):
            return f"eval/pdf/eval_null_transmission not finite: {e} {t} {pe} at {where}"
    return None


def worker(variant: str, seed: int, start: int, deadline: float, n_queries: int, inject: bool,
           inject_internal: bool = False) -> None:
    """Runs cases from `start` until `deadline`; prints `CASE i` before and `DONE i outcome`
    after each, so that the parent knows which case killed it. Outcomes: loaded, refused,
    `FAIL ...` (the contract), `SOFT ...` (the soft contract: the core's internal error)."""
    import drjit as dr
    import mitsuba as mi

    mi.set_variant(variant)
    import mitsuba_birefringent  # noqa: F401  (registers the plugins)

    log = log_capture(mi)
    i = start
    while time.time() < deadline:
        d = case(seed, i)
        print(f"CASE {i}", flush=True)
        log.messages.clear()
        if inject and i == start:
            import ctypes
            ctypes.string_at(0)  # the harness's own check: a segfault must be detected
        if inject_internal and i == start:
            # The harness's own check: the warning the plugin logs for the core's internal error.
            mi.Log(mi.LogLevel.Warn, "internal error (panic caught) (returning no light; further "
                   "errors are not reported)")
        outcome = "loaded"
        try:
            bsdf = mi.load_dict(d)
        except Exception as ex:  # the contract: a clear message naming a key
            msg = str(ex)
            outcome = "refused"
            if not msg.strip():
                outcome = "FAIL empty error message"
            elif not any(k in msg for k in keys_of(d)):
                outcome = f"FAIL error names no parameter: {type(ex).__name__}: {msg[:400]!r}"
            elif not names_a_given_parameter(msg, d):
                outcome = (f"FAIL error names {named_parameter(msg)!r}, which the dictionary does "
                           f"not give: {msg[:400]!r}")
            elif internal_errors([msg]):
                outcome = f"SOFT the core's internal error at load: {msg[:400]!r}"
        else:
            r = random.Random(seed * 7919 + i)
            problem = queries(mi, dr, bsdf, r, n_queries)
            if problem:
                outcome = f"FAIL {problem}"
        internal = internal_errors(log.messages)
        if internal and not outcome.startswith("FAIL"):
            outcome = f"SOFT the core's internal error, logged: {internal[0][:400]!r}"
        print(f"DONE {i} {outcome}", flush=True)
        i += 1
    print("END", flush=True)


def describe(d) -> str:
    return json.dumps(d, default=str, allow_nan=True)[:2000]


def run(args) -> int:
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    me = Path(__file__).resolve()
    findings, slow, soft = [], [], []
    totals = {}
    per_variant = args.seconds / len(args.variants)
    for variant in args.variants:
        deadline = time.time() + per_variant
        start, counts = 0, {"loaded": 0, "refused": 0}
        while time.time() < deadline:
            cmd = [sys.executable, str(me), "--worker", "--variant", variant, "--seed", str(args.seed),
                   "--start", str(start), "--deadline", str(deadline), "--queries", str(args.queries)]
            if args.inject_crash and start == 0:
                cmd.append("--inject-crash")
            if args.inject_internal and start == 0:
                cmd.append("--inject-internal")
            p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            lines: queue.Queue = queue.Queue()
            threading.Thread(target=lambda: [lines.put(x) for x in p.stdout] + [lines.put(None)],
                             daemon=True).start()
            current, ended, since = None, False, time.time()
            while True:
                try:
                    line = lines.get(timeout=1.0)
                except queue.Empty:
                    line = ""
                if line is None:
                    break
                if line.startswith("CASE "):
                    current, since = int(line.split()[1]), time.time()
                elif line.startswith("DONE "):
                    _, idx, outcome = line.rstrip("\n").split(" ", 2)
                    current = None
                    start = int(idx) + 1
                    if time.time() - since > SLOW:
                        slow.append((variant, int(idx), time.time() - since))
                    if outcome.startswith("FAIL") or (outcome.startswith("SOFT") and args.strict):
                        findings.append((variant, int(idx), outcome))
                    elif outcome.startswith("SOFT"):
                        soft.append((variant, int(idx), outcome))
                        counts["loaded"] += 1
                    else:
                        counts[outcome] += 1
                elif line.startswith("END"):
                    ended = True
                elif current is not None and time.time() - since > args.hang:
                    break  # one case running longer than --hang: a hang (killed below)
                elif current is not None and time.time() > deadline + GRACE:
                    break  # the budget is over during a slow case: not a finding, but listed
            if p.poll() is None:
                p.kill()
            p.wait()
            err = p.stderr.read()
            if ended and p.returncode == 0:
                break
            idx = current if current is not None else start
            took = time.time() - since
            if took > args.hang:
                findings.append((variant, idx, f"HANG: case still running after {took:.0f} s"))
            elif time.time() > deadline + GRACE and p.returncode == -9:
                slow.append((variant, idx, took))
                start = idx + 1
                break
            else:
                # The worker died by itself: a signal (crash) or an uncaught error, in case idx.
                # The message (a Rust panic or allocation failure, a Python error) if there is one,
                # else the end of the worker's standard error.
                lines_err = err.strip().splitlines()
                said = [x for x in lines_err
                        if any(w in x for w in ("panicked", "memory allocation", "Error", "error"))]
                tail = " | ".join((said or lines_err)[-3:])
                findings.append((variant, idx, f"CRASH worker exit {p.returncode}: {tail[-600:]}"))
            start = idx + 1
        totals[variant] = counts
        print(f"plugin fuzz {variant}: {start} cases, {counts['loaded']} loaded (each queried "
              f"{args.queries}x), {counts['refused']} refused with a clear message", flush=True)
    for variant, idx, took in slow:
        print(f"SLOW {variant} case {idx}: {took:.1f} s (not a failure; a hang is > {args.hang} s)\n"
              f"  dict: {describe(case(args.seed, idx))[:300]}")
    for variant, idx, what in findings:
        d = case(args.seed, idx)
        path = out / f"finding-{variant}-seed{args.seed}-case{idx}.json"
        replay = f"{sys.executable} {me} --variant {variant} --seed {args.seed} --case {idx}"
        path.write_text(json.dumps({"variant": variant, "dict": describe(d), "finding": what,
                                    "replay": replay}, indent=1))
        print(f"FINDING {variant} case {idx}: {what[:300]}\n  dict: {describe(d)[:300]}\n"
              f"  replay: {replay}\n  kept: {path}")
    for variant, idx, what in soft:
        print(f"SOFT {variant} case {idx} (not a failure without --strict): {what[:300]}\n"
              f"  replay: {sys.executable} {me} --variant {variant} --seed {args.seed} --case {idx}")
    n = sum(c["loaded"] + c["refused"] for c in totals.values()) + len(findings)
    print(f"plugin fuzz total: {n} cases, {len(findings)} findings, {len(soft)} soft findings, "
          f"{len(slow)} slow")
    return 1 if findings else 0


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seconds", type=float, default=30.0, help="total time over all variants")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--variants", nargs="+", default=list(VARIANTS))
    ap.add_argument("--variant", help="with --case or --worker: the variant")
    ap.add_argument("--queries", type=int, default=16, help="random queries per loaded BSDF")
    ap.add_argument("--out", default=str(Path(__file__).resolve().parents[2] / "target/fuzz/plugin"))
    ap.add_argument("--hang", type=float, default=300.0, help="seconds after which one case is a hang")
    ap.add_argument("--strict", action="store_true",
                    help="soft findings (the core's internal error) fail too")
    ap.add_argument("--case", type=int, help="replay one case in this process and print it")
    ap.add_argument("--inject-crash", action="store_true", help="self-check: first worker segfaults")
    ap.add_argument("--inject-internal", action="store_true",
                    help="self-check: the first case logs the core's internal-error warning")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--start", type=int, default=0, help=argparse.SUPPRESS)
    ap.add_argument("--deadline", type=float, default=0.0, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.worker:
        worker(args.variant, args.seed, args.start, args.deadline, args.queries, args.inject_crash,
               args.inject_internal)
        return 0
    if args.case is not None:
        print(describe(case(args.seed, args.case)), flush=True)
        _one(args)
        return 0
    return run(args)


def _one(args) -> None:
    import drjit as dr
    import mitsuba as mi

    mi.set_variant(args.variant or VARIANTS[-1])
    import mitsuba_birefringent  # noqa: F401

    d = case(args.seed, args.case)
    bsdf = mi.load_dict(d)
    print(bsdf)
    print(queries(mi, dr, bsdf, random.Random(args.seed * 7919 + args.case), args.queries) or "queries ok")


if __name__ == "__main__":
    sys.exit(main())
