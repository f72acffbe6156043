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


def test_plugin_fuzzer_sees_a_message_naming_a_parameter_not_given():
    """The fuzzer's naming contract catches the messages that once named the wrong parameter
    (the rotated optic axis for a NaN axis_angle, the core's index for a kappa) and accepts a
    name the dictionary gives or implies (thickness for thickness_scale, the missing eta_e)."""
    sys.path.insert(0, str(FUZZER.parent))
    import plugin_fuzz as f

    tag = '[parser.cpp:1718] At dictionary node "root": failed ...: [ThinBirefringent] '
    nan = float("nan")
    assert not f.names_a_given_parameter(tag + "optic_axis[0]: must be a finite number, got NaN",
                                         {"type": "thinbirefringent", "axis_angle": nan})
    assert not f.names_a_given_parameter(tag + "eta_e: extinction coefficient (imaginary part) "
                                         "must be <= 1000, got 1e300", {"kappa_e": 1e300})
    assert f.names_a_given_parameter(tag + "axis_angle: must be a finite number (degrees), got nan",
                                     {"axis_angle": nan})
    assert f.names_a_given_parameter(tag + "thickness: must be within [0, 1e6] µm (1 m), got -2 µm",
                                     {"thickness_scale": -2.0})
    assert f.names_a_given_parameter(tag + '"eta_e" is missing ("eta_o" is given)', {"eta_o": 1.5})
    assert f.names_a_given_parameter(tag + '"thickness" is a number (micrometres), not a colour',
                                     {"thickness": {"type": "rgb", "value": [1, 2, 3]}})
    assert f.names_a_given_parameter('The property "eta_o" has the wrong type', {"eta_o": "x"})
    assert not f.names_a_given_parameter('The property "kappa_o" has the wrong type', {"kappa_e": "x"})
