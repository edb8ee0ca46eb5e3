"""Input files and output paths (issue 12, item 1): every input file kind is read as
UTF-8 (a byte-order mark accepted) and anything else is a one-line error naming the
file and the byte; output paths are checked before any work starts; a full disk in
the middle of a run is a one-line error, not a traceback."""

from __future__ import annotations

import errno
from pathlib import Path

import pytest
from typer.testing import CliRunner

from tests.corpus.generate import CSV, PLATE, STUDY, dumps, plate_inp
from wovenimpact.cli import app

ROOT = Path(__file__).resolve().parents[2]
KEVLAR = (ROOT / "examples" / "materials" / "kevlar_thesis.toml").read_text()
SHORT = ["--set", "run.end_time=1 us"]


@pytest.fixture
def corpus(tmp_path, monkeypatch):
    """A directory with a small case, its material, a study and a CSV; cwd there."""
    (tmp_path / "kevlar.toml").write_text(KEVLAR)
    (tmp_path / "plate.toml").write_text(dumps(PLATE))
    (tmp_path / "study.toml").write_text(dumps(STUDY))
    (tmp_path / "data.csv").write_text(CSV)
    (tmp_path / "plate.inp").write_text(plate_inp())
    (tmp_path / "a_file").write_text("x\n")
    monkeypatch.chdir(tmp_path)
    return tmp_path


def invoke(*argv: str):
    return CliRunner().invoke(app, list(argv))


def assert_clean_error(result, *fragments: str) -> str:
    assert result.exception is None or isinstance(result.exception, SystemExit), \
        repr(result.exception)
    assert result.exit_code == 2, result.output
    text = " ".join(result.output.split())
    assert "error:" in text, text
    for f in fragments:
        assert f in text, text
    return text


ENCODINGS = {
    "utf16": (lambda t: t.encode("utf-16"), "is UTF-16"),
    "latin1": (lambda t: b"# \xb5m\n" + t.encode(), "is not UTF-8 (byte 0xb5 at offset 2, line 1"),
    "binary": (lambda t: bytes(range(256)), "is not text (a NUL byte at offset 0"),
}


@pytest.mark.parametrize("encoding", ENCODINGS)
@pytest.mark.parametrize("kind", ["case", "material", "study", "csv", "mesh"])
def test_a_file_that_is_not_utf8_is_a_clean_error_naming_the_file(corpus, kind, encoding):
    encode, fragment = ENCODINGS[encoding]
    name = {"case": "plate.toml", "material": "kevlar.toml", "study": "study.toml",
            "csv": "data.csv", "mesh": "plate.inp"}[kind]
    path = corpus / name
    path.write_bytes(encode(path.read_text()))
    if kind == "csv":
        result = invoke("calibrate", "compression", name, "--out", "out")
    elif kind == "study":
        result = invoke("sweep", name, "--out", "out")
    elif kind == "mesh":
        case = dict(PLATE, mesh={"kind": "abaqus", "file": name, "sections": {"plate": "fabric"}},
                    boundary=[{"nodes": "edge", "type": "clamped"}],
                    initial_velocity=[{"velocity": ["0 m/s", "0 m/s", "-5 m/s"]}])
        (corpus / "inp.toml").write_text(dumps(case))
        result = invoke("run", "inp.toml", "--out", "out", *SHORT)
    else:
        result = invoke("run", "plate.toml", "--out", "out", *SHORT)
    assert_clean_error(result, name, fragment)


def test_a_utf8_byte_order_mark_is_accepted(corpus):
    text = (corpus / "plate.toml").read_text()
    (corpus / "plate.toml").write_bytes(b"\xef\xbb\xbf" + text.encode())
    result = invoke("run", "plate.toml", "--out", "out", "--json", *SHORT)
    assert result.exit_code == 0, result.output


@pytest.mark.parametrize("argv", [
    ["run", "plate.toml", *SHORT],
    ["sweep", "study.toml"],
    ["element-test", "uniaxial", "--material", "kevlar.toml"],
    ["design", "plies", "plate.toml"],
    ["calibrate", "compression", "data.csv"],
], ids=["run", "sweep", "element-test", "design", "calibrate"])
@pytest.mark.parametrize("out, fragment", [
    ("a_file", "is an existing file, not a directory"),
    ("a_file/sub", "cannot create the directory"),
    ("/proc/wovenimpact_out", "cannot create the directory"),
])
def test_an_unusable_out_is_refused_before_any_work(corpus, monkeypatch, argv, out, fragment):
    import wovenimpact.setup.compile as compile_module

    def no_work(*a, **k):
        raise AssertionError("work started before --out was checked")

    monkeypatch.setattr(compile_module, "compile_case", no_work)
    assert_clean_error(invoke(*argv, "--out", out), f"--out {out!r}", fragment)


def test_validate_checks_its_work_and_report_paths_first(corpus):
    assert_clean_error(invoke("validate", "--work", "a_file", "--study", "hourglass"),
                       "--work 'a_file'", "existing file")
    assert_clean_error(invoke("validate", "--work", "w", "--report", "a_file/r.md",
                              "--study", "hourglass"), "--report 'a_file/r.md'")
    assert_clean_error(invoke("validate", "--work", "w", "--study", "nope"),
                       "--study 'nope'", "hourglass")


def _disk_full(*args, **kwargs):
    raise OSError(errno.ENOSPC, "No space left on device", "out/history.csv")


def test_a_full_disk_in_the_middle_of_a_run_is_a_clean_error(corpus, monkeypatch):
    import wovenimpact.runs as runs

    monkeypatch.setattr(runs, "save_checkpoint", _disk_full)  # the first checkpoint write
    result = invoke("run", "plate.toml", "--out", "out", *SHORT)
    assert_clean_error(result, "cannot write the outputs of plate.toml out/history.csv",
                       "No space left on device")


def test_a_full_disk_during_an_element_test_is_a_clean_error(corpus, monkeypatch):
    import wovenimpact.calibration.single_element as single

    monkeypatch.setattr(single, "write_history_csv", _disk_full)
    result = invoke("element-test", "uniaxial", "--material", "kevlar.toml", "--out", "out",
                    "--steps", "20")
    assert_clean_error(result, "No space left on device")


@pytest.mark.parametrize("address, fragment", [
    ("not a scheduler", "not a scheduler address"),
    ("tcp://127.0.0.1:99999", "port '99999' is not 1 to 65535"),
    ("http://host:8786", "not a scheduler address"),
])
def test_a_malformed_scheduler_is_refused_before_any_work(corpus, address, fragment):
    assert_clean_error(invoke("sweep", "study.toml", "--out", "out", "--scheduler", address),
                       f"--scheduler {address!r}", fragment)


def test_an_unreachable_scheduler_is_a_clean_error_not_a_hang(corpus, monkeypatch):
    pytest.importorskip("distributed")
    import wovenimpact.studies.sweep as sweep

    monkeypatch.setattr(sweep, "CONNECT_TIMEOUT", "1s")
    result = invoke("sweep", "study.toml", "--out", "out", "--scheduler", "tcp://127.0.0.1:9")
    assert_clean_error(result, "--scheduler 'tcp://127.0.0.1:9': no scheduler answers")


def test_a_study_parameter_with_no_values_is_an_error(corpus):
    (corpus / "empty.toml").write_text(dumps(dict(STUDY, parameters={"mesh.side": []})))
    assert_clean_error(invoke("sweep", "empty.toml", "--out", "out"), "parameters.mesh.side",
                       "at least 1 item")


def test_a_mesh_that_would_take_minutes_is_refused_before_any_work(corpus, monkeypatch):
    """0.05 mm elements on a 97 mm quarter plate (941 000 elements, 21 s and 3.5 GB to
    build) is one error line naming the count and run.allow_large_mesh, at once, not a
    silent minute; the flag lets it through to the build (here stopped by a stub)."""
    import wovenimpact.setup.compile as compile_module
    import wovenimpact.runs as runs_module

    class Built(Exception):
        pass

    def no_work(*a, **k):
        raise Built

    monkeypatch.setattr(compile_module, "compile_case", no_work)
    monkeypatch.setattr(runs_module, "compile_case", no_work)
    big = ["--set", "mesh.side=97 mm", "--set", "mesh.element_size=0.05 mm"]
    result = invoke("run", "plate.toml", "--out", "out", *SHORT, *big)
    assert_clean_error(result, "plate.toml", "mesh.element_size: gives about 9.41e+05 elements",
                       "more than 500,000", "run.allow_large_mesh = true")
    result = invoke("run", "plate.toml", "--out", "out", *SHORT, *big,
                    "--set", "run.allow_large_mesh=true")
    assert isinstance(result.exception, Built), result.output
