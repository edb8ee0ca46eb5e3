"""The energy plot of a containment run: the casing's energies on their own panel, not
flattened under the fragment's kilojoules (read through matplotlib's objects, not pixels)."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.image  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from wovenimpact.io.plots import (  # noqa: E402
    containment_energy_figure,
    energy_plot,
    single_energy_figure,
)
from wovenimpact.results.containment import CASING_ENERGY_COLUMNS  # noqa: E402
from wovenimpact.results.history_rows import HISTORY_COLUMNS  # noqa: E402

N = 41


def history(containment: bool) -> dict[str, np.ndarray]:
    """A small history: a 2.6 kJ fragment that gives the casing 300 J over 400 µs."""
    t = np.linspace(0.0, 400e-6, N)
    s = t / t[-1]
    h = {c: np.zeros(N) for c in HISTORY_COLUMNS}
    h["time_s"] = t
    h["structure_kinetic_energy_part_J"] = 3000.0 - 300.0 * s
    h["internal_work_part_J"] = 250.0 * s
    h["contact_energy_part_J"] = 50.0 * s
    h["energy_drift_part_J"] = 2.0 * s
    if containment:
        h["fragment_kinetic_energy_part_J"] = 2600.0 - 300.0 * s
        h["casing_absorbed_energy_part_J"] = 300.0 * s
        h["casing_kinetic_energy_part_J"] = 80.0 * s * (1.0 - s) * 4.0
        h["casing_element_energy_part_J"] = 60.0 * s
    return h


def labels(ax) -> list[str]:
    return [line.get_label() for line in ax.get_lines()]


def test_a_containment_energy_plot_has_the_casing_on_its_own_panel():
    h = history(containment=True)
    assert set(CASING_ENERGY_COLUMNS) <= set(h)
    fig = containment_energy_figure(h, "ring")
    try:
        top, bottom = fig.axes
        assert top.get_ylabel() == "fragment and whole model (J)"
        assert bottom.get_ylabel() == "casing (J)" and bottom.get_xlabel() == "time (µs)"
        assert "fragment kinetic" in labels(top)
        assert "fragment kinetic" not in labels(bottom)
        casing = labels(bottom)
        for name in ("casing absorbed (contact work received)", "casing kinetic",
                     "casing elements' stored + hourglass",
                     "casing dissipated (absorbed − kinetic − held)",
                     "eroded kinetic (whole model)", "balance error |drift| (whole model)"):
            assert name in casing, (name, casing)
        # the casing's axis is scaled to the casing's hundreds of joules, not to 2.6 kJ
        assert bottom.get_ylim()[1] < 400.0 < 2600.0 < top.get_ylim()[1]
        line = bottom.get_lines()[casing.index("casing dissipated (absorbed − kinetic − held)")]
        expected = (h["casing_absorbed_energy_part_J"] - h["casing_kinetic_energy_part_J"]
                    - h["casing_element_energy_part_J"])
        assert line.get_ydata() == pytest.approx(expected)
        assert line.get_xdata()[-1] == pytest.approx(400.0)  # µs
    finally:
        plt.close(fig)


def test_energy_plot_draws_two_panels_only_for_a_containment_history(tmp_path):
    fig = single_energy_figure(history(containment=False))
    try:
        assert len(fig.axes) == 1 and "structure kinetic" in labels(fig.axes[0])
    finally:
        plt.close(fig)
    heights = [matplotlib.image.imread(energy_plot(
        history(containment), tmp_path / f"energy_{containment}.png")).shape[0]
        for containment in (False, True)]
    assert heights[1] > 1.4 * heights[0]  # the written PNG: two panels, one above the other
