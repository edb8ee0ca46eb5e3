"""Pictures of the deformed structure in report.html, the per-ply history columns, and the
instants each ply was perforated: a coarse two-ply pack perforated at 900 m/s (a few
seconds), its frames read back independently of io/pictures.py."""

from __future__ import annotations

import json
import shutil
import warnings
from pathlib import Path

import meshio
import numpy as np
import pytest

from tests.io.report_page import check_run_page
from wovenimpact.io.fields import read_pvd
from wovenimpact.io.history import read_csv
from wovenimpact.io.pictures import (
    choose_frames,
    frame_polygons,
    frame_view,
    frames_of,
    read_part,
    rim_edges,
    write_pictures,
)
from wovenimpact.io.plots import event_markers, layer_energy_columns
from wovenimpact.results.quantities import ply_perforation_times
from wovenimpact.runs import run_case

ROOT = Path(__file__).resolve().parents[2]
CASE = ROOT / "examples" / "plate_impact" / "plies2_100.toml"
PERFORATING = ['mesh.side="20 mm"', 'mesh.element_size="1.25 mm"', 'impactor.velocity="900 m/s"',
               'run.end_time="30 us"', 'run.field_interval="5 us"',
               'run.history_interval="0.5 us"', 'run.checkpoint_interval="30 us"']


@pytest.fixture(scope="module")
def perforated(tmp_path_factory):
    out = tmp_path_factory.mktemp("plate") / "out"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the coarse mesh's warnings are not under test
        summary = run_case(CASE, out, overrides=PERFORATING)
    return out, summary


def alive_cells(path: Path) -> np.ndarray:
    """The ``element`` ids of the alive cells of a VTU frame, read with meshio alone."""
    m = meshio.read(path)
    alive = np.concatenate(m.cell_data["alive"]) != 0.0
    return np.concatenate(m.cell_data["element"])[alive]


def test_the_report_shows_pictures_drawn_from_the_runs_frames(perforated):
    """Each picture in the page is a decodable PNG named in pictures.json, drawn from VTU
    files the run wrote (listed in fields.pvd), with as many polygons as those frames
    have alive elements (the whole coarse pack is in view), the eroded ones not drawn."""
    out, summary = perforated
    assert summary["eroded_elements"] > 0  # so "eroded not drawn" is tested
    page = check_run_page(out)
    html = (out / "report.html").read_text()
    assert 'id="pictures"' in html
    assert html.index('id="summary"') < html.index('id="pictures"') < html.index('id="plots"')
    index = json.loads((out / "pictures" / "pictures.json").read_text())
    assert 2 <= len(index) <= 4
    alts = [alt for alt, _ in page.images]
    listed = {name for _, name in read_pvd(out / "fields" / "fields.pvd")}
    eroded_seen = 0
    for entry in index:
        assert entry["file"] in alts
        assert set(entry["vtu"]) <= listed
        alive = np.concatenate([alive_cells(out / "fields" / v) for v in entry["vtu"]])
        total = sum(sum(len(c) for c in meshio.read(out / "fields" / v).cell_data["alive"])
                    for v in entry["vtu"])
        assert entry["drawn"] == entry["alive_in_view"] == alive.size
        assert entry["elements_in_view"] == total
        eroded_seen = max(eroded_seen, total - alive.size)
        assert f'data-drawn="{alive.size}"' in html
    assert eroded_seen > 0  # a picture with holes: eroded elements hidden
    # the first picture is the first frame at or after first contact
    h = read_csv(out / "history.csv")
    force = np.abs(h["contact_force_full_N"])
    t_contact = h["time_s"][np.flatnonzero(force > 0.01 * force.max())[0]]
    times = [t for _, t, _ in frames_of(out / "fields")]
    assert index[0]["time_s"] == min(t for t in times if t >= t_contact)
    assert index[-1]["time_s"] == times[-1]


def test_an_eroded_element_is_not_drawn(perforated, tmp_path):
    """A frame with one more element marked eroded draws one polygon fewer, and not that
    element; the polygons drawn are exactly the alive cells of the frame."""
    out, _ = perforated
    src = out / "fields" / "step_000001.vtu"
    part = read_part(src)
    view = frame_view({"": part})
    before = frame_polygons({"": part}, view)
    ids = np.concatenate(meshio.read(src).cell_data["element"])
    assert sorted(before.elements.tolist()) == sorted(alive_cells(src).tolist())
    m = meshio.read(src)
    alive = [a.copy() for a in m.cell_data["alive"]]
    conn = part.connectivity
    live = alive[0] != 0.0

    def neighbours(e):  # the cells sharing an edge with cell e
        mine = {frozenset(p) for p in zip(conn[e], np.roll(conn[e], -1))}
        return [f for f, c in enumerate(conn) if f != e
                and any(frozenset(p) in mine for p in zip(c, np.roll(c, -1)))]

    # an alive cell whose edge-neighbours are all alive (its hole has a whole rim)
    victim = next(e for e in np.flatnonzero(live)
                  if len(neighbours(e)) >= 2 and all(live[f] for f in neighbours(e)))
    alive[0][victim] = 0.0
    m.cell_data["alive"] = alive
    copy = tmp_path / "step_000001.vtu"
    meshio.write(copy, m)
    after = frame_polygons({"": read_part(copy)}, view)
    assert after.corners.shape[0] == before.corners.shape[0] - 1
    assert ids[victim] not in after.elements and ids[victim] in before.elements
    # its hole is outlined: one rim segment per edge it shares with a drawn cell, lying
    # on its own corners as drawn (a victim inside the pack has four such neighbours)
    shared = len(neighbours(victim))  # one edge each (quads of one ply)

    def segments(rim):
        return {frozenset(tuple(np.round(x, 12)) for x in seg) for seg in rim}

    new = segments(after.rim) - segments(before.rim)
    corners = {tuple(np.round(x, 12))
               for x in before.corners[before.elements.tolist().index(ids[victim])]}
    assert shared >= 2 and len(new) == shared
    assert all(x in corners for seg in new for x in seg)


def test_the_rim_of_a_hole_is_the_edges_eroded_cells_share_with_drawn_ones():
    """Three quads in a row, the middle one eroded: its two shared edges are the rim, one
    from each neighbour; a triangle (a repeated corner) contributes no degenerate edge;
    nothing eroded, no rim."""
    conn = np.array([[0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 8, 7, 7]])
    rim = rim_edges(conn, np.array([0, 2, 3]), np.array([1]))
    assert sorted(map(tuple, rim.tolist())) == [(0, 1), (1, 3)]  # quad 0's edge 1-5, quad 2's 6-2
    assert rim_edges(conn, np.array([0, 1, 2]), np.array([3])).tolist() == [[2, 1]]  # 3-7
    assert rim_edges(conn, np.array([0, 1, 2, 3]), np.array([], dtype=int)).shape == (0, 2)


def test_per_ply_columns_and_perforation_instants(perforated):
    """The per-ply contact work columns end at the summary's contact work per ply; every
    ply is perforated, the ply struck first (the top one) first; the instants are those
    the history's flags give, and they and the decided outcome are marked."""
    out, summary = perforated
    h = read_csv(out / "history.csv")
    assert summary["outcome"] == "perforated"
    factor = summary["symmetry_factor"]
    cols = layer_energy_columns(h)
    assert cols == ["ply0_contact_work_part_J", "ply1_contact_work_part_J"]
    assert [factor * h[c][-1] for c in cols] == summary["contact_work_per_ply_J"]
    times = summary["ply_perforated_at_s"]
    assert times == ply_perforation_times(h) and None not in times
    # ply 1 is on top (the impactor comes down along −z): struck and perforated first
    assert times[1] <= times[0]
    for p, t in enumerate(times):
        rows = np.flatnonzero(h["time_s"] < t)
        assert np.all(h[f"ply{p}_intact_ahead"][rows] == 1)  # intact before its instant
    # the whole pack is perforated no earlier than its last ply, and decided later still
    first_clear = h["time_s"][np.flatnonzero(h["intact_material_ahead"] == 0)[0]]
    assert first_clear == max(times)
    assert summary["outcome_decided_at_s"] >= first_clear
    labels = [label for _, label in event_markers(times, summary["outcome_decided_at_s"])]
    assert "outcome decided" in labels
    assert (out / "plots" / "layer_energy.png").stat().st_size > 1000


def test_choose_frames_starts_at_first_contact_and_ends_at_the_last():
    times = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0]
    assert choose_frames(times, 2.5) == [3, 4, 6, 7]
    assert choose_frames(times, None) == [0, 2, 5, 7]
    assert choose_frames(times, 10.0) == [7]
    assert choose_frames([0.0, 1.0], 0.5) == [1]
    assert choose_frames([], 0.0) == []


def test_pictures_of_a_copied_run_are_redrawn(perforated, tmp_path):
    """write_pictures reads only the run's folder: a copy of it draws the same pictures
    (same frames and counts), its older PNGs replaced."""
    out, _ = perforated
    copy = tmp_path / "copy"
    shutil.copytree(out, copy)
    (copy / "pictures" / "frame_999999.png").write_bytes(b"stale")
    again = write_pictures(copy, read_csv(copy / "history.csv"))
    first = json.loads((out / "pictures" / "pictures.json").read_text())
    assert [(e["frame"], e["drawn"]) for e in again] == [(e["frame"], e["drawn"]) for e in first]
    assert not (copy / "pictures" / "frame_999999.png").exists()
