"""Kill a run after a checkpoint and restart it: the check every restart test makes."""

from __future__ import annotations

from pathlib import Path

from wovenimpact.io.checkpoint import latest_checkpoint, load_checkpoint
from wovenimpact.runs import run_case
from wovenimpact.setup.compile import compile_case
from wovenimpact.spec.case import load_case


def interrupted_and_resumed(case: Path, out: Path, fraction: float):
    """Run ``case`` whole into ``out/whole``, then into ``out/broken`` stopped after
    ``fraction`` of its steps (it must report the interruption) and restarted from its
    newest checkpoint; both history.csv files must be equal. Returns (the whole run's
    summary, the two folders, the two final checkpoints' States) for the caller's own
    checks of the State and the frames."""
    whole, broken = out / "whole", out / "broken"
    full = run_case(case, whole)
    partial = run_case(case, broken, max_steps=int(fraction * full["steps"]))
    assert "interrupted_at_step" in partial
    run_case(case, broken, restart=True)
    assert (whole / "history.csv").read_text() == (broken / "history.csv").read_text()
    spec, base = load_case(case)
    digest = compile_case(spec, base).model.digest()
    a = load_checkpoint(latest_checkpoint(whole / "checkpoints"), digest)
    b = load_checkpoint(latest_checkpoint(broken / "checkpoints"), digest)
    return full, whole, broken, a, b
