"""docs/performance.md is rewritten by benchmarks/performance_page.py from the figures the
benchmarks save (``make bench``): a section with figures is replaced, one without is kept,
and the text around the sections is never touched."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PAGE = ROOT / "docs" / "performance.md"


def writer():
    spec = importlib.util.spec_from_file_location("performance_page",
                                                  ROOT / "benchmarks" / "performance_page.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


MACHINE = {"cpu": "Test CPU", "cores": 2, "numba_threads": 2, "system": "Linux",
           "python": "3.11.7", "numba": "0.68.1", "wovenimpact": "0.1.0", "date": "2030-01-02"}
SHELL = {"machine": MACHINE, "cases": [
    {"name": "elastic_plate", "elements": 10000, "threads": 1, "ns_per_element_cycle": 300.4,
     "bytes_per_element": 1234.0, "ratio_to_elastic": 1.0},
    {"name": "fabric_plate", "elements": 10000, "threads": 1, "ns_per_element_cycle": 642.6,
     "bytes_per_element": 2345.0, "ratio_to_elastic": 2.139}]}
KERNEL = {"cases": [{"name": "fabric_point_update", "crossover": "table", "points": 200000,
                     "threads": 1, "ns_per_point_update": 123.46, "iterations_mean": 0.0,
                     "iterations_max": 0}]}
CONTACT = {"cases": [{"plies": 6, "threads": 2, "nodes": 14406, "ns_per_node": 617.0,
                      "reused_ns_per_node": 207.0, "broad_ns_per_node": 301.0,
                      "book_ns_per_node": 12.0}]}
RUN = {"machine": "machine: Test CPU, 2 cores", "case": "examples/containment/hybrid_10.toml",
       "element_size": "5.5 mm", "end_time": "4 ms", "threads": 2, "elements": 57284,
       "steps": 6244, "wall_time_s": 382.2, "ns_per_element_cycle": 1068.0,
       "ratio_to_target": 2.123, "target_s": 180.0, "outcome": "escaped",
       "fragment_initial_speed_m_per_s": 150.4, "fragment_exit_speed_m_per_s": 114.1,
       "energy_error_fraction": 7.2e-4, "hourglass_fraction": 0.036,
       "added_mass_fraction": 0.0021}


def save(directory: Path, **docs) -> None:
    directory.mkdir(parents=True, exist_ok=True)
    for name, doc in docs.items():
        (directory / f"{name}.json").write_text(json.dumps(doc))


def test_the_page_has_the_sections_the_benchmarks_write():
    names = writer().section_names(PAGE.read_text(encoding="utf-8"))
    assert names == ["bench", "flagship", "containment"], names


def test_figures_rewrite_their_section_and_keep_the_rest(tmp_path):
    page = tmp_path / "performance.md"
    original = PAGE.read_text(encoding="utf-8")
    page.write_text(original, encoding="utf-8")
    save(tmp_path / "bench", fabric_kernel=KERNEL, shell=SHELL, contact=CONTACT,
         containment=RUN)
    writer().main([f"--dir={tmp_path / 'bench'}", f"--page={page}"])
    text = page.read_text(encoding="utf-8")
    w = writer()
    old = dict(zip(w.section_names(original), w.SECTION.findall(original)))
    new = dict(zip(w.section_names(text), w.SECTION.findall(text)))
    # the bench section: the machine line of the run and every figure it saved
    bench = new["bench"][1]
    assert "`machine: Test CPU, 2 cores (2 Numba threads), Linux, Python 3.11.7, numba 0.68.1, " \
           "wovenimpact 0.1.0, 2030-01-02`" in bench
    for figure in ("| fabric_plate | 10 000 | 1 | 643 | 2345 | 2.14 |", "| table | 200 000 | 1 | "
                   "123.5 |", "| 6 | 2 | 14 406 | 617 | 207 | 301 | 12 |"):
        assert figure in bench, figure
    assert "**382.2 s** of run" in new["containment"][1] and "2.12× the 180 s target" in \
        new["containment"][1]
    # the flagship had no figures: kept as it was; the text outside the sections untouched
    assert new["flagship"] == old["flagship"]
    assert w.SECTION.sub("", text) == w.SECTION.sub("", original)


def test_without_figures_the_page_is_unchanged(tmp_path):
    page = tmp_path / "performance.md"
    page.write_text(PAGE.read_text(encoding="utf-8"), encoding="utf-8")
    writer().main([f"--dir={tmp_path / 'none'}", f"--page={page}"])
    assert page.read_text(encoding="utf-8") == PAGE.read_text(encoding="utf-8")
