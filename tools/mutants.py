#!/usr/bin/env python3
"""Mutation testing (`make mutants`): applies each mutation of tests/mutants/mutants.toml, one at a
time, to a scratch copy of the repository, rebuilds what it touches, runs the tests that claim to
cover it, and reports which mutations the tests kill and which survive.

A mutation is a precise textual patch: `file`, the exact `old` text (which must occur exactly
once: a mutation whose text no longer matches is stale and stops the run before anything is
built), the `new` text, and `tests`, the commands that claim to cover it (argument lists run from
the copy's root; `pytest` and `cargo` stand for this interpreter's pytest and cargo). A mutation
is killed when one of its commands fails (or runs past --timeout), and survives when all pass.

The copy (default target/mutants/repo: the files `git ls-files` lists, tracked and untracked
but not ignored) keeps its own cargo target directory between mutations and between runs, so a
rebuild is incremental. Its Python package is the one imported: the tests run with this
interpreter (the .venv/ of `make setup`, whose editable install points at the ORIGINAL plugin/)
with PYTHONPATH starting with the copy's plugin/ directory, which Python searches before the
editable install's .pth entry; MITSUBA_BIREFRINGENT_LIBRARY is unset. Before the first mutation
and after each rebuild a subprocess with the same environment imports the package and checks
that `mitsuba_birefringent.__file__` and the plugin library mapped into the process lie in the
copy. A mutation of compiled code (src/, cpp/, the build files) is built by its `cargo test`
commands (compiled first with --no-run) and, when pytest covers it, into the calculator and the
plugin library (`cargo build --release`, `make plugin-lib`), which must then differ from the
unmutated library (else the tests would see the unmutated one); the unmutated library is rebuilt
before a Python-only mutation that follows. A restored file is written anew (a fresh
modification time), so that cargo rebuilds it; a mutation that does not build is an error, not a
kill.

Standard library only. Usage: tools/mutants.py [--only ID[,ID...]] [--baseline] [--show]
[--list FILE] [--scratch DIR] [--timeout SECONDS]; logs in <scratch>/logs/<id>.log.
"""

from __future__ import annotations

import argparse
import hashlib
import os
import re
import shutil
import signal
import subprocess
import sys
import sysconfig
import time
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_LIST = ROOT / "tests" / "mutants" / "mutants.toml"
DEFAULT_SCRATCH = ROOT / "target" / "mutants"
LIBRARY = Path("plugin/mitsuba_birefringent/libmitsuba_birefringent.so")
#: Files whose mutation needs cargo and the plugin library rebuilt.
COMPILED = ("src/", "cpp/", "build.rs", "Cargo.toml", "Cargo.lock")
#: Lines of a failing command's output shown in the report.
TAIL = 12


@dataclass
class Mutant:
    id: str
    file: str
    old: str
    new: str
    tests: list[list[str]]
    why: str = ""
    audit: str = ""
    result: str = "not run"
    by: str = ""
    seconds: float = 0.0
    log: list[str] = field(default_factory=list)

    @property
    def compiled(self) -> bool:
        return self.file.startswith(COMPILED)


def load(path: Path) -> list[Mutant]:
    """The mutations of `path`, each checked against the repository (fails loudly if stale)."""
    with open(path, "rb") as f:
        data = tomllib.load(f)
    mutants, seen, errors = [], set(), []
    for i, entry in enumerate(data.get("mutant", [])):
        missing = {"id", "file", "old", "new", "tests"} - entry.keys()
        if missing:
            errors.append(f"mutant #{i + 1}: missing {sorted(missing)}")
            continue
        m = Mutant(**{k: entry[k] for k in ("id", "file", "old", "new", "tests", "why", "audit")
                      if k in entry})
        if m.id in seen:
            errors.append(f"{m.id}: duplicate id")
        seen.add(m.id)
        mutants.append(m)
        target = ROOT / m.file
        if not target.is_file():
            errors.append(f"{m.id}: {m.file} does not exist")
            continue
        count = target.read_text().count(m.old)
        if count != 1:
            errors.append(f"{m.id}: stale mutation: its old text occurs {count} times in {m.file} "
                          "(must be exactly once); update tests/mutants/mutants.toml")
        if m.old == m.new:
            errors.append(f"{m.id}: old and new texts are equal")
        if not m.tests or not all(isinstance(c, list) and c for c in m.tests):
            errors.append(f"{m.id}: tests must be a non-empty list of commands (argument lists)")
        else:
            errors += [f"{m.id}: {e}" for e in missing_tests(m.tests)]
    if errors:
        raise SystemExit("mutants: the list is not valid:\n  " + "\n  ".join(errors))
    return mutants_in_order(mutants)


def missing_tests(commands: list[list[str]]) -> list[str]:
    """The test files a list of commands names that do not exist (pytest paths, cargo --test)."""
    missing = []
    for argv in commands:
        if argv[0] == "pytest":
            paths = [a.split("::")[0] for a in argv[1:] if a.split("::")[0].endswith(".py")]
        elif argv[0] == "cargo":
            paths = [f"tests/{argv[i + 1]}.rs" for i, a in enumerate(argv[:-1]) if a == "--test"]
        else:
            paths = []
        missing += [f"{p} does not exist" for p in paths if not (ROOT / p).is_file()]
    return missing


def mutants_in_order(mutants: list[Mutant]) -> list[Mutant]:
    """Python-only mutations first (no rebuild), then compiled ones grouped by file."""
    return sorted(mutants, key=lambda m: (m.compiled, m.file if m.compiled else ""))


# -- the scratch copy --------------------------------------------------------------------------

def repository_files() -> list[str]:
    out = subprocess.run(["git", "ls-files", "-co", "--exclude-standard", "-z"], cwd=ROOT,
                         capture_output=True, check=True).stdout.decode()
    return sorted(p for p in out.split("\0") if p and (ROOT / p).is_file())


def sync(copy: Path) -> None:
    """Makes `copy` hold the repository's files; a file whose content differs is rewritten (a
    fresh modification time, so that cargo and make rebuild it), equal ones are left alone, and
    files of an earlier sync that are gone are removed."""
    manifest = copy / ".mutants-manifest"
    files = repository_files()
    previous = set(manifest.read_text().split("\n")) if manifest.exists() else set()
    for rel in sorted(previous - set(files) - {""}):
        (copy / rel).unlink(missing_ok=True)
    changed = 0
    for rel in files:
        src, dst = ROOT / rel, copy / rel
        data = src.read_bytes()
        if not dst.is_file() or dst.read_bytes() != data:
            dst.parent.mkdir(parents=True, exist_ok=True)
            dst.write_bytes(data)
            shutil.copymode(src, dst)
            changed += 1
    manifest.write_text("\n".join(files))
    print(f"mutants: {copy} synced ({len(files)} files, {changed} written)")


class Scratch:
    """The copy, its environment and its builds."""

    def __init__(self, base: Path, timeout: float):
        self.copy = base / "repo"
        self.logs = base / "logs"
        self.copy.mkdir(parents=True, exist_ok=True)
        self.logs.mkdir(parents=True, exist_ok=True)
        self.timeout = timeout
        self.python = sys.executable
        self.cargo = os.environ.get("CARGO") or shutil.which("cargo") or str(
            Path.home() / ".cargo" / "bin" / "cargo")
        env = dict(os.environ)
        env.pop("MITSUBA_BIREFRINGENT_LIBRARY", None)
        env.pop("MAKEFLAGS", None)
        env.pop("MFLAGS", None)
        paths = [str(self.copy / "plugin"), str(self.copy / "tests" / "python")]
        if env.get("PYTHONPATH"):
            paths.append(env["PYTHONPATH"])
        env.update(PYTHONPATH=os.pathsep.join(paths), PYTHONDONTWRITEBYTECODE="1",
                   CARGO_TARGET_DIR=str(self.copy / "target"), CARGO=self.cargo)
        self.env = env
        self.dirty = False  # the package holds a mutated library
        self.clean_digest = ""  # the unmutated library's
        self.offset = 0  # where the last command's output starts in its log

    def command(self, argv: list[str]) -> list[str]:
        """`argv` with `pytest` and `cargo` resolved."""
        if argv[0] == "pytest":
            return [self.python, "-m", "pytest", "-q", "-x", "-p", "no:cacheprovider", *argv[1:]]
        if argv[0] == "cargo":
            return [self.cargo, *argv[1:]]
        return list(argv)

    def run(self, argv: list[str], log: Path, timeout: float | None = None) -> tuple[str, str]:
        """Runs `argv` in the copy: ("ok" | "failed" | "timeout", the output's last lines)."""
        self.offset = log.stat().st_size if log.exists() else 0
        with open(log, "ab") as out:
            out.write(f"\n$ {' '.join(argv)}\n".encode())
            out.flush()
            proc = subprocess.Popen(argv, cwd=self.copy, env=self.env, stdout=out,
                                    stderr=subprocess.STDOUT, start_new_session=True)
            try:
                rc = proc.wait(timeout=timeout or self.timeout)
                status = "ok" if rc == 0 else "failed"
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)
                proc.wait()
                status = "timeout"
        lines = log.read_text(errors="replace").splitlines()
        return status, "\n".join(lines[-TAIL:])

    def build(self, log: Path) -> tuple[bool, str]:
        """cargo build (library and calculator) and the plugin library, incrementally."""
        site = sysconfig.get_paths()["purelib"]
        for argv in ([self.cargo, "build", "--release"],
                     ["make", "--no-print-directory", "plugin-lib", f"SITE={site}",
                      f"CARGO={self.cargo}", f"VPY={self.python}"]):
            status, tail = self.run(argv, log, timeout=3600)
            if status != "ok":
                return False, tail
        return True, ""

    def failed_test(self, log: Path) -> str:
        """The first failing test the last command's output names (pytest's or cargo's)."""
        with open(log, "rb") as f:
            f.seek(self.offset)
            text = f.read().decode(errors="replace")
        for line in text.splitlines():
            hit = re.match(r"FAILED (\S+)", line) or re.match(r"test (\S+) \.\.\. FAILED", line)
            if hit:
                return hit.group(1)
        return ""

    def rebuild_unmutated(self, log: Path) -> None:
        ok, tail = self.build(log)
        if not ok:
            raise SystemExit(f"mutants: the unmutated copy does not build:\n{tail}")
        self.check_imports()
        self.dirty = False
        self.clean_digest = self.library_digest()

    def library_digest(self) -> str:
        path = self.copy / LIBRARY
        return hashlib.sha256(path.read_bytes()).hexdigest() if path.is_file() else ""

    def check_imports(self) -> None:
        """The package and plugin library a test imports are the copy's (see the docstring)."""
        probe = ("import mitsuba_birefringent as m, pathlib\n"
                 "lib = {l.split()[-1] for l in open('/proc/self/maps') "
                 "if l.rstrip().endswith('libmitsuba_birefringent.so')}\n"
                 "print(pathlib.Path(m.__file__).resolve()); print(*sorted(lib), sep='\\n')\n")
        out = subprocess.run([self.python, "-c", probe], cwd=self.copy, env=self.env,
                             capture_output=True, text=True)
        if out.returncode != 0:
            raise SystemExit(f"mutants: importing the copy's package failed:\n{out.stderr}")
        package, *libraries = out.stdout.split()
        copy = str(self.copy.resolve())
        if not package.startswith(copy + os.sep):
            raise SystemExit(f"mutants: the tests would import {package}, not the copy's package "
                             f"under {copy}")
        if not libraries or any(not p.startswith(copy + os.sep) for p in libraries):
            raise SystemExit(f"mutants: the tests would load the plugin library {libraries}, not "
                             f"the copy's {copy / LIBRARY}")


# -- one mutation -----------------------------------------------------------------------------

def run_mutant(m: Mutant, s: Scratch) -> None:
    log = s.logs / f"{m.id}.log"
    log.write_text(f"mutation {m.id}: {m.file}\n--- old\n{m.old}\n+++ new\n{m.new}\n")
    target = s.copy / m.file
    original = target.read_text()
    if original.count(m.old) != 1:
        raise SystemExit(f"mutants: {m.id}: the copy's {m.file} does not hold the old text once")
    python = any(c[0] == "pytest" for c in m.tests)
    start = time.monotonic()
    if python and not m.compiled and s.dirty:
        s.rebuild_unmutated(log)  # an earlier mutation's library is still in the package
    target.write_text(original.replace(m.old, m.new))
    try:
        if m.compiled and python:
            # cargo test builds what it runs; pytest needs the calculator and the plugin library.
            s.dirty = True
            ok, tail = s.build(log)
            if not ok:
                m.result, m.by, m.log = "UNBUILDABLE", "build", tail.splitlines()
                return
            s.check_imports()
            if s.library_digest() == s.clean_digest:
                m.result, m.by = "ERROR", "the plugin library did not change"
                return
        for argv in m.tests:
            if argv[0] == "cargo" and argv[1:2] == ["test"]:
                status, tail = s.run(s.command(argv[:2] + ["--no-run"] + argv[2:]), log)
                if status != "ok":
                    m.result, m.by, m.log = "UNBUILDABLE", " ".join(argv), tail.splitlines()
                    return
            status, tail = s.run(s.command(argv), log)
            if status != "ok":
                m.result = "killed" if status == "failed" else "killed (timeout)"
                m.by, m.log = s.failed_test(log) or " ".join(argv), tail.splitlines()
                return
        m.result, m.by = "SURVIVED", "all passed: " + "; ".join(" ".join(c) for c in m.tests)
    finally:
        m.seconds = time.monotonic() - start
        target.write_text(original)  # a fresh mtime: the next build sees the restored file


def baseline(mutants: list[Mutant], s: Scratch) -> None:
    """Every covering command passes on the unmutated copy (else a 'kill' would mean nothing)."""
    log = s.logs / "baseline.log"
    log.write_text("baseline\n")
    commands = []
    for m in mutants:
        commands += [c for c in m.tests if c not in commands]
    for argv in commands:
        status, tail = s.run(s.command(argv), log)
        print(f"  baseline {'ok  ' if status == 'ok' else 'FAIL'} {' '.join(argv)}", flush=True)
        if status != "ok":
            raise SystemExit(f"mutants: a covering command fails without any mutation:\n{tail}")


def report(mutants: list[Mutant], wall: float) -> bool:
    width = max(len(m.id) for m in mutants)
    print(f"\n{'mutation':<{width}}  {'result':<16} {'time':>7}  killed by / note")
    for m in mutants:
        print(f"{m.id:<{width}}  {m.result:<16} {m.seconds:6.0f}s  {m.by}")
    bad = [m for m in mutants if not m.result.startswith("killed")]
    for m in bad:
        print(f"\n{m.id} ({m.file}): {m.result}; {m.why}")
        for line in m.log:
            print(f"    {line}")
    killed = len(mutants) - len(bad)
    print(f"\n{killed} of {len(mutants)} mutations killed, {len(bad)} not; wall time "
          f"{wall / 60:.1f} min")
    return not bad


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--list", type=Path, default=DEFAULT_LIST, help="the mutations (TOML)")
    ap.add_argument("--only", default="", help="comma-separated ids to run")
    ap.add_argument("--scratch", type=Path, default=DEFAULT_SCRATCH,
                    help="where the copy, its build and the logs live")
    ap.add_argument("--timeout", type=float, default=1800.0,
                    help="seconds a covering command may take (beyond: killed, timeout)")
    ap.add_argument("--baseline", action="store_true",
                    help="first run every covering command on the unmutated copy")
    ap.add_argument("--show", action="store_true", help="list the mutations and exit")
    args = ap.parse_args()
    mutants = load(args.list)
    if args.only:
        wanted = set(args.only.split(","))
        unknown = wanted - {m.id for m in mutants}
        if unknown:
            raise SystemExit(f"mutants: unknown ids {sorted(unknown)}")
        mutants = [m for m in mutants if m.id in wanted]
    if args.show:
        for m in mutants:
            print(f"{m.id}: {m.file} — {m.why}\n    tests: {m.tests}")
        return 0
    start = time.monotonic()
    s = Scratch(args.scratch.resolve(), args.timeout)
    sync(s.copy)
    print("mutants: building the unmutated copy (incremental after the first run)", flush=True)
    (s.logs / "build.log").write_text("")
    s.rebuild_unmutated(s.logs / "build.log")
    if args.baseline:
        baseline(mutants, s)
    for i, m in enumerate(mutants):
        print(f"[{i + 1}/{len(mutants)}] {m.id} ({m.file}) ...", end=" ", flush=True)
        run_mutant(m, s)
        print(f"{m.result} in {m.seconds:.0f}s" + (f" by {m.by}" if m.by else ""), flush=True)
    return 0 if report(mutants, time.monotonic() - start) else 1


if __name__ == "__main__":
    sys.exit(main())
