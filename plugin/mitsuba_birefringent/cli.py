"""``mitsuba-birefringent``: Mitsuba 3's command-line renderer for XML scenes, with the plugins
``thinbirefringent``, ``birefringentstack`` and ``birefringent`` registered.

Mitsuba's own ``mitsuba`` command cannot render a scene that uses them (it reports
``Plugin "birefringent" not found``: it only knows the plugins shipped in its wheel). This
command takes the options of ``mitsuba`` 3.9.1 with the same meaning::

    mitsuba-birefringent -m scalar_spectral_polarized -D spp=64 -o out.exr scene.xml

and renders each scene with its own integrator, writing the film of the chosen sensor (by
default next to the scene file, with the film's extension, as ``mitsuba`` does). ``-o`` writes
the format its extension names, where ``mitsuba`` would write its film's format whatever the
extension: ``.exr`` the film (every channel), ``.hdr`` or ``.pfm`` its RGB (or luminance)
channels in floating point, ``.png``, ``.jpg`` or ``.jpeg`` those in 8-bit sRGB (clamped to
[0, 1], as ``mi.util.convert_to_bitmap`` writes them); another extension is refused before the
render. One option is added: ``--spp N`` overrides the sampler's sample count. ``-V`` (the LLVM
vector width) is not supported. In the JIT variants scenes render in Mitsuba's default mode; where a plate or
stack is integrated over colour channels or a band (its core query runs on the host), the render is done again
in Dr.Jit's evaluated mode, which that query needs (``mitsuba_birefringent.evaluated_mode``).
"""

from __future__ import annotations

import argparse
import contextlib
import sys
from pathlib import Path

import drjit as dr
import mitsuba as mi

import mitsuba_birefringent
from mitsuba_birefringent.jit import EVALUATED_ONLY
from mitsuba_birefringent.names import listed

#: Dr.Jit flags that mitsuba's `-O <level>` switches on successively (off above the level).
OPTIMIZATION_FLAGS = ("MergeFunctions", "ConstantPropagation", "ValueNumbering", "OptimizeCalls",
                      "OptimizeLoops")
#: Mitsuba's log levels for 0, 1 and 2 or more `-v`.
LOG_LEVELS = ("Info", "Debug", "Trace")
#: What `-o` writes by its extension: the film itself (all its channels), its RGB or luminance
#: channels in floating point, or those in 8-bit sRGB.
FILM_EXTENSIONS = (".exr",)
FLOAT_EXTENSIONS = (".hdr", ".pfm")
SRGB_EXTENSIONS = (".png", ".jpg", ".jpeg")


def parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="mitsuba-birefringent",
        description=f"Render Mitsuba 3 XML scenes with the birefringent BSDFs {listed()} "
                    "registered (the options of Mitsuba's `mitsuba` command).")
    p.add_argument("scenes", nargs="+", metavar="scene.xml", help="one or more scene XML files")
    p.add_argument("-m", "--mode", metavar="VARIANT",
                   help="the Mitsuba variant (default: %(default)s, the first of the variants the "
                        "plugins support: " + ", ".join(mitsuba_birefringent.VARIANTS) + ")",
                   default=mitsuba_birefringent.VARIANTS[0])
    p.add_argument("-v", "--verbose", action="count", default=0,
                   help="be more verbose (can be given several times)")
    p.add_argument("-t", "--threads", type=int, metavar="COUNT",
                   help="render with this number of threads")
    p.add_argument("-D", "--define", action="append", default=[], metavar="KEY=VALUE",
                   help='define a constant that the scene references as "$KEY"')
    p.add_argument("-s", "--sensor", type=int, default=0, metavar="INDEX",
                   help="index of the sensor to render with (declaration order; default 0)")
    p.add_argument("-a", dest="paths", action="append", default=[], metavar="PATH1;PATH2",
                   help="add entries to the resource search path")
    p.add_argument("-o", "--output", metavar="FILENAME",
                   help="write the image to this file, in the format its extension names: "
                        ".exr (the film), .hdr, .pfm (its RGB channels), .png, .jpg (8-bit sRGB) "
                        "(default: the scene's path with the film's extension)")
    p.add_argument("--spp", type=int, metavar="N",
                   help="samples per pixel, overriding the scene's sampler (not in `mitsuba`)")
    jit = p.add_argument_group("JIT (llvm/cuda) variants only")
    jit.add_argument("-O", dest="optimize", type=int, choices=range(6), metavar="[0-5]",
                     help="enable successive optimisations (default 5)")
    jit.add_argument("-S", dest="print_ir", action="store_true",
                     help="print the intermediate representation of the kernels")
    jit.add_argument("-W", dest="wavefront", action="count", default=0,
                     help="render in wavefronts instead of a megakernel (twice: also unroll calls)")
    p.add_argument("--version", action="version",
                   version=f"%(prog)s {mitsuba_birefringent.__version__} (Mitsuba {mi.__version__})")
    return p


def defines(pairs: list[str]) -> dict[str, str]:
    """The `-D key=value` pairs as the parameters of `mi.load_file`."""
    out = {}
    for pair in pairs:
        key, sep, value = pair.partition("=")
        if not sep or not key:
            raise ValueError(f"-D/--define: expected key=value, got {pair!r}")
        out[key] = value
    return out


def set_jit_flags(args: argparse.Namespace) -> None:
    """`-O`, `-W`, `-S` as Dr.Jit flags (refused outside the JIT variants, as `mitsuba` does)."""
    if args.optimize is None and not args.wavefront and not args.print_ir:
        return
    if not args.mode.startswith(("llvm_", "cuda_")):
        raise ValueError("-O, -S and -W only make sense in a JIT (llvm/cuda) variant")
    if args.optimize is not None:
        for level, name in enumerate(OPTIMIZATION_FLAGS):
            dr.set_flag(getattr(dr.JitFlag, name), args.optimize > level)
    if args.wavefront:
        dr.set_flag(dr.JitFlag.SymbolicLoops, False)
    if args.wavefront > 1:
        dr.set_flag(dr.JitFlag.SymbolicCalls, False)
    if args.print_ir:
        dr.set_flag(dr.JitFlag.PrintIR, True)


def add_search_paths(entries: list[str]) -> None:
    """`-a path1;path2`: appended to the file resolver (scene directories come first)."""
    resolver = mi.file_resolver()
    for entry in entries:
        for path in filter(None, entry.split(";")):
            if path not in [str(p) for p in resolver]:
                resolver.append(path)


def render_file(path: Path, params: dict[str, str], args: argparse.Namespace) -> None:
    """Loads one scene, renders it with its integrator and writes the chosen sensor's film."""
    scene = mi.load_file(str(path), **params)
    if not isinstance(scene, mi.Scene):
        raise ValueError(f"{path}: the root element must be a <scene> tag")
    sensors = scene.sensors()
    if not sensors:
        raise ValueError(f"{path}: the scene has no sensor")
    if not 0 <= args.sensor < len(sensors):
        raise ValueError(f"sensor index {args.sensor} is out of bounds (the scene has {len(sensors)})")
    integrator = scene.integrator()
    if integrator is None:
        raise ValueError(f"{path}: the scene has no integrator")
    def render() -> None:
        integrator.render(scene, sensor=args.sensor, seed=0, spp=args.spp or 0, develop=False,
                          evaluate=True)

    with thread_count(args.threads):
        try:
            render()  # Mitsuba's default mode: the plugins' physics inside its kernels
        except RuntimeError as e:
            if EVALUATED_ONLY not in str(e):
                raise
            # A plate or stack over colour channels or a band: its query runs on the host.
            with mitsuba_birefringent.evaluated_mode():
                render()
    film = sensors[args.sensor].film()
    if args.output is None:
        film.write(str(path))  # the film's own format, next to the scene (as `mitsuba`)
    else:
        write_image(film, Path(args.output))


def check_output(output: str | None) -> None:
    """Refuses an `-o` whose extension names no format this command writes (before rendering)."""
    if output is None:
        return
    ext = Path(output).suffix.lower()
    if ext not in FILM_EXTENSIONS + FLOAT_EXTENSIONS + SRGB_EXTENSIONS:
        raise ValueError(f"-o {output}: cannot write {ext or 'a file without extension'}; give "
                         ".exr (the film, every channel), .hdr or .pfm (its RGB channels) or "
                         ".png, .jpg (8-bit sRGB)")


def write_image(film, path: Path) -> None:
    """Writes `film` to `path` in the format its extension names (module docstring)."""
    ext = path.suffix.lower()
    if ext in FILM_EXTENSIONS:
        film.write(str(path))
        return
    colour = dict(film.bitmap().split())["<root>"]  # RGB (or Y in the mono variants)
    if ext in FLOAT_EXTENSIONS:
        colour.write(str(path))
    else:
        mi.util.convert_to_bitmap(colour).write(str(path))


@contextlib.contextmanager
def thread_count(threads: int | None):
    """`-t N` while rendering: N threads, the calling one included (a pool of N - 1 workers, as
    `mitsuba` sets it). The pool is restored before the image is written: Mitsuba 3.9.1's EXR
    writer runs on the same pool and deadlocks once it has been resized (so does `mitsuba -t`)."""
    if threads is None:
        yield
        return
    if threads < 1:
        mi.Log(mi.LogLevel.Warn, "the thread count must be at least 1; using 1")
    default = dr.thread_count()
    dr.set_thread_count(max(threads, 1) - 1)
    try:
        yield
    finally:
        dr.set_thread_count(default)


def run(args: argparse.Namespace) -> None:
    if args.mode not in mi.variants():
        raise ValueError(f"unknown variant {args.mode!r}; this Mitsuba has {', '.join(mi.variants())}")
    if args.spp is not None and args.spp < 1:
        raise ValueError(f"--spp must be at least 1, got {args.spp}")
    params = defines(args.define)
    check_output(args.output)
    set_jit_flags(args)
    mi.set_variant(args.mode)
    mi.set_log_level(getattr(mi.LogLevel, LOG_LEVELS[min(args.verbose, 2)]))
    add_search_paths(args.paths)
    mi.Log(mi.LogLevel.Info, f"Rendering using the \"{args.mode}\" variant "
                             f"(mitsuba_birefringent {mitsuba_birefringent.__version__}).")
    for scene in args.scenes:
        render_file(Path(scene), params, args)


def main(argv: list[str] | None = None) -> int:
    """The console script; returns the exit status (0, or 1 after an error message)."""
    args = parser().parse_args(argv)
    try:
        run(args)
    except Exception as e:  # every failure of a render is reported, as `mitsuba` does
        if args.verbose:
            raise
        print(f"mitsuba-birefringent: error: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
