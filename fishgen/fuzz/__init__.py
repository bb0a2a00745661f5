"""Fuzzing harness: mutated species/cube files, glTF/OBJ/PLY assets and CLI options.

Every input must either succeed (and write only finite outputs) or fail with
:class:`fishgen.errors.FishgenError` (the CLI: exit status 2, one line on stderr). Cases
run in persistent worker processes under an address-space and per-case time budget.
See docs/fuzzing.md; run ``python -m fishgen.fuzz --help``.
"""
from __future__ import annotations

from fishgen.fuzz.cases import TARGETS, make_case, run_case
from fishgen.fuzz.inputs import Case, load_seeds
from fishgen.fuzz.runner import Finding, Report, run
from fishgen.fuzz.verdict import Outcome

__all__ = ["TARGETS", "Case", "Finding", "Outcome", "Report", "load_seeds", "make_case", "run", "run_case"]
