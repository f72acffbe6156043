"""The list of `make mutants` (tests/mutants/mutants.toml) stays applicable: every mutation's old
text occurs exactly once in its file and every covering test exists (tools/mutants.py refuses
the list otherwise, before building anything), and the runner refuses a stale mutation. The
mutations themselves run only under `make mutants` (each needs a rebuild)."""

from __future__ import annotations

import importlib.util
import pathlib
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


def runner():
    spec = importlib.util.spec_from_file_location("mutants", ROOT / "tools" / "mutants.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["mutants"] = module  # dataclasses look their module up there
    spec.loader.exec_module(module)
    return module


def test_every_mutation_of_the_list_applies():
    mutants = runner().load(ROOT / "tests" / "mutants" / "mutants.toml")
    assert len(mutants) >= 12
    for m in mutants:
        assert (ROOT / m.file).read_text().count(m.old) == 1, m.id


def test_a_stale_mutation_or_a_missing_test_is_refused(tmp_path):
    path = tmp_path / "stale.toml"
    path.write_text('[[mutant]]\nid = "gone"\nfile = "src/lib.rs"\nold = "no such text in lib.rs"\n'
                    'new = "x"\ntests = [["cargo", "test", "--test", "no_such_test"]]\n')
    with pytest.raises(SystemExit) as e:
        runner().load(path)
    message = str(e.value)
    assert "stale mutation: its old text occurs 0 times in src/lib.rs" in message
    assert "tests/no_such_test.rs does not exist" in message
