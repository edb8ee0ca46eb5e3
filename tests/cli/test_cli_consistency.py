"""CLI consistency: ``--version``, choice options that validate (and list their
choices), more threads than cores warned of, and a shortened run that just runs."""

from __future__ import annotations

import typing
from pathlib import Path

import numba
import pytest
from typer.testing import CliRunner

import wovenimpact
from wovenimpact.cli.app import app
from wovenimpact.cli.element_test import Failure, Frame, Homogenisation, ShearLaw
from wovenimpact.errors import InputWarning
from wovenimpact.jit import capped_threads
from wovenimpact.materials.fabric import FabricOptions

ROOT = Path(__file__).resolve().parents[2]
KEVLAR = ROOT / "examples" / "materials" / "kevlar_thesis.toml"
TOUR = ROOT / "examples" / "cases" / "fabric_plate_impulse.toml"


def test_version():
    result = CliRunner().invoke(app, ["--version"])
    assert result.exit_code == 0
    assert result.stdout.strip() == f"wovenimpact {wovenimpact.__version__}"


@pytest.mark.parametrize("enum, option", [
    (Homogenisation, "homogenisation"), (ShearLaw, "shear"), (Frame, "frame"),
    (Failure, "failure"),
])
def test_element_test_choices_are_the_material_options(enum, option):
    hints = typing.get_type_hints(FabricOptions)
    assert [e.value for e in enum] == list(typing.get_args(hints[option]))


@pytest.mark.parametrize("option, bad", [
    ("--frame", "greennaghdi"), ("--shear-law", "false"), ("--homogenisation", "mean"),
    ("--failure", "slow"),
])
def test_a_bad_choice_is_refused_before_running_and_lists_the_choices(tmp_path, option, bad):
    result = CliRunner().invoke(app, ["element-test", "shear", "--material", str(KEVLAR),
                                      "--out", str(tmp_path / "o"), option, bad])
    assert result.exit_code == 2
    assert bad in result.output and "is not one of" in result.output
    assert not (tmp_path / "o").exists()


def test_a_good_choice_runs(tmp_path):
    result = CliRunner().invoke(app, ["element-test", "shear", "--material", str(KEVLAR),
                                      "--out", str(tmp_path / "o"), "--frame", "green-naghdi",
                                      "--steps", "20", "--json"])
    assert result.exit_code == 0, result.output
    assert (tmp_path / "o" / "summary.json").exists()


def test_more_threads_than_cores_warns_and_names_the_cap():
    top = numba.config.NUMBA_NUM_THREADS
    with pytest.warns(InputWarning, match=f"--threads = {top + 7} .* using {top}"):
        assert capped_threads(top + 7, "--threads") == top
    assert capped_threads(1, "--threads") == 1


def test_a_shortened_run_with_too_many_threads_runs_and_warns(tmp_path):
    out = tmp_path / "out"
    result = CliRunner().invoke(app, [
        "run", str(TOUR), "--out", str(out), "--threads", "64", "--json",
        "--set", 'run.end_time="1 us"', "--set", 'mesh.side="10 mm"',
        "--set", 'mesh.element_size="1.88 mm"'])
    assert result.exit_code == 0, result.output
    err = result.stderr
    assert "warning: --threads = 64 is more than" in err
    assert "warning:" in err and "run.checkpoint_interval = 25 us" in err
    assert (out / "summary.json").exists()


def test_design_layers_says_it_takes_a_containment_case():
    """``design layers`` is ``design plies`` under the name a casing designer looks for:
    its help names the containment case it is for (it called its argument a
    "plate-impact case")."""
    def help_text(name):  # the words of the help, rich's box lines left out
        out = CliRunner().invoke(app, ["design", name, "--help"]).output
        return " ".join(out.replace("│", " ").split())

    for name in ("plies", "layers"):
        assert "or a containment case (a casing and a blade" in help_text(name), name
    assert "Another name of `design plies`" in help_text("layers")
