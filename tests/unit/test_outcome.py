"""The outcome rule of an impact (quantities.residual_velocity) on synthetic histories.

Each history is built from a few physical facts — when contact starts and ends, how
much the impactor slows, when its nose passes the last intact surface — sampled at a
history interval that may be finer or much coarser than the rule's quiet time. The
properties are the ones a user relies on: never ``perforated`` while intact material
is ahead of the nose or contact has not been quiet for ``QUIET_TIME``; ``no contact``
(and not perforated) when it never arrived; the residual of a clean perforation is its
final velocity; a rebound is ``stopped`` with its rebound speed.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wovenimpact.errors import InputError
from wovenimpact.results.quantities import OUTCOMES, QUIET_TIME, residual_velocity

US = 1e-6


def history(t_end, interval, v, force, ahead) -> dict:
    """Rows every ``interval`` up to ``t_end`` (the last row at t_end, as a run writes
    it) of the functions v(t), force(t), ahead(t)."""
    t = np.arange(0.0, t_end, interval)
    t = np.append(t, t_end) if t[-1] < t_end else t
    return {"time_s": t,
            "impactor_velocity_m_per_s": np.array([v(x) for x in t], dtype=float),
            "contact_force_full_N": np.array([force(x) for x in t], dtype=float),
            "intact_material_ahead": np.array([int(ahead(x)) for x in t], dtype=np.int64)}


def check(result: dict) -> dict:
    assert result["outcome"] in OUTCOMES
    assert result["perforated"] == (result["outcome"] == "perforated")
    return result


intervals = st.sampled_from([0.05 * US, 0.5 * US, 2 * US, 7 * US, 20 * US])
speeds = st.floats(5.0, 1500.0)


@settings(max_examples=200, deadline=None)
@given(v0=speeds, loss=st.floats(0.0, 1e-3), t_end=st.floats(12 * US, 400 * US),
       interval=intervals, period=st.floats(0.2 * US, 30 * US), duty=st.floats(0.0, 1.0))
def test_heavy_body_pushing_intact_plies_is_undecided(v0, loss, t_end, interval, period, duty):
    """A heavy impactor barely slowed (≤ 0.1 %) while it pushes intact material: the
    force may be a train of spikes with zeros between (some samples see none for longer
    than the quiet time), the velocity is steady — still ``undecided``, never perforated."""
    def force(x):
        return 0.0 if x < 1 * US or (x / period) % 1.0 >= duty else 5e3

    h = history(t_end, interval, lambda x: v0 * (1.0 - loss * min(x / t_end, 1.0)),
                force, lambda x: True)
    h["contact_force_full_N"][1] = 5e3  # it did arrive
    r = check(residual_velocity(h))
    assert r["outcome"] == "undecided"
    assert not r["perforated"]


@settings(max_examples=200, deadline=None)
@given(v0=speeds, t_contact=st.floats(1 * US, 100 * US), after=st.floats(0.0, QUIET_TIME),
       interval=intervals, passed=st.booleans())
def test_run_ending_soon_after_contact_is_not_perforated(v0, t_contact, after, interval, passed):
    """Contact starts at t_c and the run ends less than the quiet time later: the nose
    may even be past the material already (a thin ply torn at once), but contact has not
    been quiet for QUIET_TIME, so the outcome is ``undecided``."""
    t_end = t_contact + after
    h = history(t_end, interval, lambda x: v0 if x < t_contact else 0.9 * v0,
                lambda x: 1e3 if x >= t_contact else 0.0,
                lambda x: not (passed and x >= t_contact))
    if not np.any(h["contact_force_full_N"] > 0):
        return  # no row saw the contact (coarse sampling): covered by the no-contact test
    r = check(residual_velocity(h))
    assert r["outcome"] == "undecided"


@settings(max_examples=300, deadline=None)
@given(v0=speeds, loss=st.floats(0.01, 0.9), t1=st.floats(0.5 * US, 50 * US),
       duration=st.floats(0.5 * US, 60 * US), tail=st.floats(0.0, 200 * US),
       interval=intervals)
def test_clean_perforation_is_called_only_after_a_quiet_time(v0, loss, t1, duration, tail,
                                                             interval):
    """Contact from t1 to t2 slows the impactor by ``loss``; its nose passes the last
    intact surface at t2 and the force drops to nothing. Whatever the history interval:
    perforated only if the run went on for the quiet time after t2 (a coarse interval can
    only delay the call, by at most one interval), and then with the final velocity as
    the residual; before that, undecided."""
    t2 = t1 + duration
    t_end = t2 + tail
    v_res = v0 * (1.0 - loss)

    def v(x):
        return v0 - (v0 - v_res) * min(max((x - t1) / duration, 0.0), 1.0)

    h = history(t_end, interval, v, lambda x: 2e3 if t1 <= x < t2 else 0.0,
                lambda x: x < t2)
    r = check(residual_velocity(h))
    if tail < QUIET_TIME:
        assert r["outcome"] in ("undecided", "no contact") and not r["perforated"]
    if r["outcome"] == "perforated":
        assert r["residual_velocity_m_per_s"] == pytest.approx(v_res, rel=1e-12)
        assert r["rebound_velocity_m_per_s"] == 0.0
    touched = np.any(h["contact_force_full_N"] > 0) or np.ptp(h["impactor_velocity_m_per_s"]) > 0
    if touched and tail >= QUIET_TIME + 2 * interval:
        assert r["outcome"] == "perforated"


@settings(max_examples=100, deadline=None)
@given(v0=speeds, t_end=st.floats(1 * US, 300 * US), interval=intervals,
       ahead=st.booleans())
def test_impactor_that_never_arrives_is_no_contact_and_not_perforated(v0, t_end, interval,
                                                                      ahead):
    """No contact force in any row and an unchanged velocity: ``no contact``, not
    perforated — whether the plate is still ahead (run too short) or there is nothing
    within its radius (a hole)."""
    h = history(t_end, interval, lambda x: v0, lambda x: 0.0, lambda x: ahead)
    r = check(residual_velocity(h))
    assert r["outcome"] == "no contact" and not r["perforated"]
    assert r["residual_velocity_m_per_s"] == v0


def test_contact_seen_only_through_the_velocity_is_not_no_contact():
    """A contact shorter than the history interval leaves no force in any row, but the
    velocity changed: the impactor did arrive, so the run is not ``no contact``."""
    h = history(100 * US, 20 * US, lambda x: 300.0 if x < 30 * US else 280.0,
                lambda x: 0.0, lambda x: x < 30 * US)
    r = check(residual_velocity(h))
    assert r["outcome"] == "perforated" and r["residual_velocity_m_per_s"] == 280.0


@settings(max_examples=200, deadline=None)
@given(v0=speeds, back=st.floats(0.0, 0.8), t_turn=st.floats(5 * US, 100 * US),
       tail=st.floats(0.0, 100 * US), interval=intervals, still_touching=st.booleans())
def test_rebound_is_stopped_with_its_rebound_speed(v0, back, t_turn, tail, interval,
                                                   still_touching):
    """The impactor slows to zero at t_turn and comes back at ``back`` × v0 (in contact
    or not at the end): ``stopped``, residual 0, rebound speed = −(final velocity)."""
    t_end = t_turn + tail

    def v(x):
        return v0 * (1.0 - x / t_turn) if x < t_turn else -back * v0 * min((x - t_turn) / 5e-6, 1.0)

    h = history(t_end, interval, v,
                lambda x: 1e3 if x < t_turn + 5e-6 or still_touching else 0.0,
                lambda x: True)
    if np.min(h["impactor_velocity_m_per_s"]) > 0.0:
        return  # sampling never saw it turn (the end row is at t_turn at the latest)
    r = check(residual_velocity(h))
    assert r["outcome"] == "stopped" and not r["perforated"]
    assert r["residual_velocity_m_per_s"] == 0.0
    assert r["rebound_velocity_m_per_s"] == pytest.approx(
        max(0.0, -h["impactor_velocity_m_per_s"][-1]))


def test_impactor_at_rest_against_intact_material_is_stopped():
    """Slowed to 0.5 % of its speed, pressed on an intact ply: stopped, no rebound."""
    h = history(50 * US, 1 * US, lambda x: 100.0 * max(1.0 - x / (40 * US), 0.005),
                lambda x: 1e3, lambda x: True)
    r = check(residual_velocity(h))
    assert r == {"outcome": "stopped", "perforated": False, "residual_velocity_m_per_s": 0.0,
                 "rebound_velocity_m_per_s": 0.0}


def test_debris_striking_from_behind_is_not_an_engagement():
    """After the perforation a fragment hits the impactor from behind (a force along
    the travel, negative here): the contact counts as ended."""
    h = history(60 * US, 0.5 * US, lambda x: 200.0 if x < 10 * US else 150.0,
                lambda x: 3e3 if 5 * US <= x < 10 * US else (-500.0 if 40 * US <= x else 0.0),
                lambda x: x < 10 * US)
    r = check(residual_velocity(h))
    assert r["outcome"] == "perforated" and r["residual_velocity_m_per_s"] == 150.0


def test_history_without_the_geometry_columns_is_refused_by_name():
    h = history(50 * US, 1 * US, lambda x: 100.0, lambda x: 0.0, lambda x: True)
    del h["intact_material_ahead"]
    with pytest.raises(InputError, match="intact_material_ahead"):
        residual_velocity(h)
