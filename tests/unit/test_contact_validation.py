"""The impactor-contact section of the validation report (reports/contact_validation.py)."""

from __future__ import annotations

import json

from wovenimpact.reports.contact_validation import smith_strip_lines, strip_figure
from wovenimpact.verification.strip_impact import StripImpact, strip_impact


def test_the_section_tabulates_each_speed_against_smith(tmp_path):
    """From cached rows (no run): each speed's measured force, kink speed and strain
    beside the theory's, with the signed error, and its figure linked."""
    theory = {"force_N": 467.8, "kink_speed": 281.7, "strain": 0.00333}
    rows = [{"speed_m_per_s": 100.0, "figure": "strip_impact_100.png", "theory": theory,
             "force_N": 463.2, "force_error": 463.2 / 467.8 - 1.0,
             "kink_speed_m_per_s": 285.7, "kink_speed_error": 285.7 / 281.7 - 1.0,
             "strain": 0.00334, "strain_error": 0.00334 / 0.00333 - 1.0,
             "max_stray_from_face_m": 4.0e-5}]
    (tmp_path / "smith_strip.json").write_text(json.dumps(rows))
    text = "\n".join(smith_strip_lines(tmp_path, tmp_path))
    assert ("| 100 m/s | 463.2 (-1.0%) | 467.8 | 285.7 (+1.4%) | 281.7 | 0.00334 (+0.3%) | "
            "0.00333 | 0.040 |") in text
    assert "(validation/strip_impact_100.png)" in text


def test_the_figure_is_drawn_from_a_run(tmp_path):
    """A short, coarse run draws a PNG of its force and kink histories."""
    r = strip_impact(StripImpact(element_size=0.5e-3, end_time=2e-6, settle=0.5e-6))
    path = strip_figure(r, tmp_path / "strip.png")
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert len(r["history"]["time_s"]) == len(r["history"]["contact_force_N"]) > 10
