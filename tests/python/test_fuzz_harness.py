"""The plugin-parameter fuzzer (tests/fuzz/plugin_fuzz.py) sees a crash: its worker process is
made to segfault on its first case (--inject-crash), and the fuzzer must report that case as a
finding, keep it, go on with the next cases in a new worker, and exit 1; and with --strict (as
`make test` runs it) the core's internal error, which shows only in Mitsuba's log, fails the run
(--inject-internal). Without this, a fuzzer whose detection is broken would pass forever."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

FUZZER = Path(__file__).resolve().parents[1] / "fuzz" / "plugin_fuzz.py"


def test_plugin_fuzzer_reports_a_segfault(tmp_path):
    out = subprocess.run(
        [sys.executable, str(FUZZER), "--seconds", "6", "--variants", "scalar_spectral",
         "--inject-crash", "--out", str(tmp_path), "--queries", "2"],
        capture_output=True, text=True, timeout=300)
    assert out.returncode == 1, out.stdout + out.stderr
    found = sorted(tmp_path.glob("finding-scalar_spectral-seed1-case0.json"))
    assert found, out.stdout
    finding = json.loads(found[0].read_text())
    assert finding["finding"].startswith("CRASH worker exit -11"), finding  # SIGSEGV
    # It went on after the crash: later cases ran in a new worker.
    line = next(x for x in out.stdout.splitlines() if x.startswith("plugin fuzz scalar_spectral:"))
    assert int(line.split(":")[1].split()[0]) > 1, line


def test_plugin_fuzzer_strict_fails_on_the_core_internal_error(tmp_path):
    """The core's internal error (a caught panic, a refused non-finite result) reaches the
    renderer only as one logged warning and no light: finite numbers, so only the log shows it.
    The worker is made to log that warning on its first case (--inject-internal): without
    --strict it is listed as a soft finding and the run passes, with --strict (as in `make test`)
    it is a finding and the run fails."""
    args = [sys.executable, str(FUZZER), "--seconds", "3", "--variants", "scalar_spectral",
            "--inject-internal", "--queries", "2"]
    lenient = subprocess.run(args + ["--out", str(tmp_path / "lenient")], capture_output=True,
                             text=True, timeout=300)
    assert lenient.returncode == 0, lenient.stdout + lenient.stderr
    assert "SOFT scalar_spectral case 0" in lenient.stdout, lenient.stdout
    strict = subprocess.run(args + ["--strict", "--out", str(tmp_path / "strict")],
                            capture_output=True, text=True, timeout=300)
    assert strict.returncode == 1, strict.stdout + strict.stderr
    finding = json.loads((tmp_path / "strict" / "finding-scalar_spectral-seed1-case0.json").read_text())
    assert finding["finding"].startswith("SOFT the core's internal error"), finding
