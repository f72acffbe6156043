"""pytest's set-up of tests/python: Dr.Jit's LLVM target from the environment (llvm_target.py:
BIREFRINGENT_LLVM_WIDTH, BIREFRINGENT_LLVM_CPU, BIREFRINGENT_LLVM_FEATURES), so that a run at
another vector width than the machine's is one command."""

from __future__ import annotations

import llvm_target

_TARGET = llvm_target.apply()


def pytest_report_header(config):
    return _TARGET
