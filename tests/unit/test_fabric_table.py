"""Tabulated crossover (theory §1.9): envelope theorem, Hermite interpolation, accuracy
against the exact solve, and the kernel's use of the table."""

from __future__ import annotations

import dataclasses
import os

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.conftest import reference_fabric, with_options
from tests.unit.test_fabric_kernel import scaled_parameters, stretch_shear
from wovenimpact.errors import InputError
from wovenimpact.kernels import fabric_layout as L
from wovenimpact.kernels.fabric_table import crossover_from_table_for_points
from wovenimpact.materials import fabric_table as FT
from wovenimpact.materials.fabric import initial_state, update_points

TOL = FT.TOLERANCE  # 1e-4: tensions / T_u, heights / h0, energy / W_u


def table_row(params):
    return with_options(params, crossover="table").to_array()


def exact_row(params):
    return with_options(params, crossover="exact").to_array()


def layout(row):
    return (*FT.table_knots(row), FT.table_data(row))


@pytest.mark.parametrize("lam_w, lam_f", [(1.02, 1.0), (1.04, 1.01), (1.01, 1.035), (1.05, 0.95),
                                          (0.99, 1.045)])
def test_gradient_of_the_minimum_is_the_partial_at_the_equilibrium_heights(lam_w, lam_f):
    """Envelope theorem: dW/dλ_i by central differences of the exact W equals
    2 T_i cosψ_i ℓ_i0 / A0 at the equilibrium heights."""
    params = reference_fabric()
    h = 1e-6
    ex = FT.exact_crossover(params, lam_w, lam_f)
    w_pw = FT.exact_crossover(params, [lam_w + h, lam_w - h], lam_f)["W"]
    w_pf = FT.exact_crossover(params, lam_w, [lam_f + h, lam_f - h])["W"]
    assert float(ex["W_w"]) == pytest.approx((w_pw[0] - w_pw[1]) / (2 * h), rel=1e-6)
    assert float(ex["W_f"]) == pytest.approx((w_pf[0] - w_pf[1]) / (2 * h), rel=1e-6)
    assert float(ex["W_w"]) > 0 and float(ex["W_f"]) > 0  # both yarns in contact


def test_interpolant_reproduces_knot_values_and_gradients():
    params = reference_fabric()
    row = table_row(params)
    kw, kf, data = layout(row)
    rng = np.random.default_rng(3)
    i = rng.integers(0, len(kw), 200)
    j = rng.integers(0, len(kf), 200)
    out = np.empty((200, 6))
    # the knot's own cell must be interpolated: evaluate with the exact-cell marks off
    row = row.copy()
    _, _, d = layout(row)
    d[..., L.T_EXACT] = 0.0
    crossover_from_table_for_points(row, kw[i], kf[j], out)
    assert np.all(out[:, 0] == 1.0)
    for col, q in ((1, L.T_W), (2, L.T_W + 1), (3, L.T_W + 2), (4, L.T_HW), (5, L.T_HF)):
        ref = data[i, j, q]
        assert np.allclose(out[:, col], ref, rtol=1e-12, atol=1e-12 * np.abs(data[..., q]).max())


def test_table_covers_compression_to_beyond_failure_and_marks_few_cells_exact():
    params = reference_fabric()
    kw, kf, data = layout(table_row(params))
    assert kw[0] == FT.LAMBDA_MIN and kw[-1] > FT.failure_stretch(params.warp)
    assert np.all(np.diff(kw) > 0) and np.all(np.diff(kf) > 0)
    frac = data[:-1, :-1, L.T_EXACT].mean()
    print(f"\ntable {len(kw)} × {len(kf)} knots, {frac:.1%} of the cells solved exactly")
    assert 0.0 < frac < 0.05


def test_a_failure_stretch_beyond_the_table_limit_is_an_input_error_naming_the_field():
    """"Failure off" as T_u = 1 MN would ask for a grid of ~10⁹ cells (a run that ate all
    memory before its first step); the largest allowed T_u is the inverse of λ_u."""
    params = reference_fabric()
    big = dataclasses.replace(params.fill, ultimate_tension=1e6)
    with pytest.raises(InputError, match=r"fill\.ultimate_tension = 1e\+06 N .* λ_u = "):
        FT.family_knots(big, params.warp, family="fill")
    limit = FT._tension_at(params.fill, FT.MAX_FAILURE_STRETCH)
    at = dataclasses.replace(params.fill, ultimate_tension=limit)
    assert FT.failure_stretch(at) == pytest.approx(FT.MAX_FAILURE_STRETCH, rel=1e-12)
    FT.family_knots(dataclasses.replace(at, ultimate_tension=0.999 * limit), params.warp)


def test_a_family_without_crimp_is_an_input_error_not_a_zero_over_zero():
    """h0 = 0 (crimp 0) made the builder divide by h0 in its height norms (a RuntimeWarning
    from 0/0) and run; the material files refuse it (test_strict_inputs), and so does the
    table, naming the family, for parameters made in code."""
    import warnings

    params = reference_fabric()
    straight = dataclasses.replace(params.warp, crimp=0.0, h0=0.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(InputError, match=r"^warp\.h0 = 0 m \(crimp 0\): the crossover "
                                             r"table needs crimped yarns"):
            FT.family_knots(straight, params.fill, family="warp")
        with pytest.raises(InputError, match=r"^fill\.h0 = 0 m"):
            FT.with_table(dataclasses.replace(params, fill=dataclasses.replace(
                params.fill, crimp=0.0, h0=0.0)), np.zeros(L.N_PARAM))


def sample_errors(params, n, seed):
    rng = np.random.default_rng(seed)
    lu = max(FT.failure_stretch(params.warp), FT.failure_stretch(params.fill))
    lw = rng.uniform(FT.LAMBDA_MIN, lu, n)
    lf = rng.uniform(FT.LAMBDA_MIN, lu, n)
    return lw, lf, FT.table_errors(params, table_row(params), lw, lf)


def test_table_matches_the_exact_solve_up_to_failure():
    """Target of issue 13: < 1e-4 on tensions (/T_u), heights (/h0, states in contact)
    and energy (/W_u) over [0.8, λ_u]², every state before failure."""
    params = reference_fabric()
    lw, lf, err = sample_errors(params, 200_000, 11)
    err.pop("contact")
    for key, e in err.items():
        k = int(np.nanargmax(e))
        print(f"\n{key}: max {e[k]:.2e} at λ = ({lw[k]:.5f}, {lf[k]:.5f}), "
              f"median {np.nanmedian(e):.1e}, {np.sum(~np.isnan(e))} states", end="")
        assert e[k] < TOL, key


@settings(max_examples=12, deadline=None)
@given(scale=st.lists(st.floats(10**-0.5, 10**0.5), min_size=8, max_size=8))
def test_table_accuracy_holds_over_the_property_test_materials(scale):
    """The materials of the solver's property test (each constant scaled by up to √10):
    each gets its own table and the same accuracy target."""
    params = scaled_parameters(scale)
    _, _, err = sample_errors(params, 20_000, 5)
    err.pop("contact")
    for key, e in err.items():
        assert np.nanmax(e) < TOL, (key, np.nanmax(e))


def test_the_undeformed_state_and_its_neighbourhood_are_tabulated():
    """The undeformed state λ = (1, 1) lies on the onset of contact, whose cells are
    solved exactly; the cluster of knots 1 ± REST_STEPS makes the cells around it small
    enough that the heights are unique there to the tolerance, so a fabric at rest (most
    of every model, most of the time) is evaluated from the table: exactly the unloaded
    crossover at the knot (1, 1), the target accuracy within 1e-6 of it and over the
    cluster's span. Fails when the rest cells are marked exact (before the cluster)."""
    params = reference_fabric()
    row = table_row(params)
    out = np.empty((1, 6))
    crossover_from_table_for_points(row, np.array([1.0]), np.array([1.0]), out)
    inside, w, gw, gf, hw, hf = out[0]
    assert inside == 1.0 and w == 0.0 and gw == 0.0 and gf == 0.0
    assert hw == pytest.approx(params.warp.h0, rel=1e-12)
    assert hf == pytest.approx(params.fill.h0, rel=1e-12)
    rng = np.random.default_rng(7)
    near = 1.0 + rng.uniform(-1e-6, 1e-6, (2, 20_000))
    out = np.empty((near.shape[1], 6))
    crossover_from_table_for_points(row, near[0].copy(), near[1].copy(), out)
    assert out[:, 0].all()  # every state within 1e-6 of rest: the table
    span = 1.0 + rng.uniform(-FT.REST_STEPS[-1], FT.REST_STEPS[-1], (2, 20_000))
    for lam in (near, span):
        err = FT.table_errors(params, row, lam[0], lam[1])
        err.pop("contact")
        for key, e in err.items():
            assert np.nanmax(e) < TOL, (key, np.nanmax(e))


def intact(state):
    return (state[:, L.S_DAMAGE] == 0) & (state[:, L.S_DAMAGE + 1] == 0)


def test_kernel_with_table_matches_exact_kernel_on_random_states():
    """fabric_point with the table against the exact solve: tensions, heights, energy,
    resultant; sheared states too (shear is exact in both)."""
    params = reference_fabric()
    rng = np.random.default_rng(5)
    n = 20_000
    f_new = np.array([stretch_shear(*rng.uniform(0.85, 1.06, 2), rng.uniform(-0.9, 0.9))
                      for _ in range(n)])
    f_old = np.repeat(np.eye(2)[None], n, axis=0)
    s0 = initial_state(params, n)
    ex = update_points(exact_row(params), f_old, f_new, s0)
    tb = update_points(table_row(params), f_old, f_new, s0)
    assert np.array_equal(ex.state[:, L.S_DAMAGE:L.S_DAMAGE + 2], tb.state[:, L.S_DAMAGE:L.S_DAMAGE + 2])
    ok = intact(ex.state)
    solved = ok & (ex.state[:, L.S_ITER] > 0)  # states where the exact option iterates
    used = solved & (tb.state[:, L.S_ITER] == 0)
    print(f"\ntable used in {used.sum()} of {solved.sum()} states in contact")
    assert used.sum() > 0.9 * solved.sum()  # the table did the work
    tu = params.warp.ultimate_tension
    for c in (L.S_TENSION, L.S_TENSION + 1):
        assert np.max(np.abs(tb.state[ok, c] - ex.state[ok, c])) < TOL * tu
    nscale = np.abs(ex.resultant[ok]).max()
    print(f"\nresultant: max error {np.abs(tb.resultant[ok] - ex.resultant[ok]).max() / nscale:.1e} of its max")
    assert np.abs(tb.resultant[ok] - ex.resultant[ok]).max() < TOL * nscale
    wu = FT.reference_scales(params)["W"]
    assert np.max(np.abs(tb.state[ok, L.S_ENERGY] - ex.state[ok, L.S_ENERGY])) < TOL * wu
    assert np.all(tb.stiffness[ok] > 0)


def test_resultant_is_the_derivative_of_the_tabulated_energy():
    """Conservative by construction: P = ∂W/∂F of the interpolant, by central differences
    of the kernel's own stored energy (sheared, stretched state)."""
    params = reference_fabric()
    p = table_row(params)
    f = stretch_shear(1.031, 1.012, 0.3)
    s0 = initial_state(params)[0]

    def energy(fm):
        return update_points(p, np.eye(2), fm, s0).state[0, L.S_ENERGY]

    upd = update_points(p, np.eye(2), f, s0)
    assert upd.state[0, L.S_ITER] == 0  # interpolated
    n = upd.resultant[0]
    nm = np.array([[n[0], n[2]], [n[2], n[1]]])
    piola = np.linalg.det(f) * nm @ np.linalg.inv(f).T
    h = 1e-7
    fd = np.zeros((2, 2))
    for a in range(2):
        for b in range(2):
            dp, dm = f.copy(), f.copy()
            dp[a, b] += h
            dm[a, b] -= h
            fd[a, b] = (energy(dp) - energy(dm)) / (2 * h)
    assert np.allclose(piola, fd, rtol=1e-6, atol=1e-6 * np.abs(piola).max())


@pytest.mark.parametrize("damage", [(0.3, 0.0), (0.0, 1.0)])
def test_damaged_states_use_the_exact_solve(damage):
    params = reference_fabric()
    s = initial_state(params)[0]
    s[L.S_DAMAGE], s[L.S_DAMAGE + 1] = damage
    f = np.diag([1.03, 1.01])
    a = update_points(exact_row(params), np.eye(2), f, s)
    b = update_points(table_row(params), np.eye(2), f, s)
    assert np.array_equal(a.state, b.state) and np.array_equal(a.resultant, b.resultant)


def test_outside_the_table_uses_the_exact_solve():
    params = reference_fabric()
    s = initial_state(params)[0]
    f = np.diag([0.7, 1.02])  # λ_w below the table
    a = update_points(exact_row(params), np.eye(2), f, s)
    b = update_points(table_row(params), np.eye(2), f, s)
    assert np.array_equal(a.state, b.state) and np.array_equal(a.resultant, b.resultant)


def test_failure_detected_from_the_table_then_solved_exactly():
    """A uniaxial pull past T_u: the table's tension trips the failure, the exact solve
    then unloads the broken warp the same way as the exact option does."""
    params = reference_fabric()
    s = initial_state(params)[0]
    f = np.diag([1.06, 1.0])  # T_w > T_u (a straight warp fails at λ = 1.0572)
    a = update_points(exact_row(params), np.eye(2), f, s)
    b = update_points(table_row(params), np.eye(2), f, s)
    assert a.state[0, L.S_DAMAGE] == 1.0 and b.state[0, L.S_DAMAGE] == 1.0
    assert np.array_equal(a.state[0, L.S_TENSION:L.S_TENSION + 2], b.state[0, L.S_TENSION:L.S_TENSION + 2])


def test_green_naghdi_frame_keeps_the_exact_solve():
    params = reference_fabric(frame="green-naghdi", crossover="table")
    assert params.to_array()[L.P_CROSSOVER] == L.CROSSOVER_EXACT


def test_table_is_built_once_per_material():
    params = reference_fabric()
    a = table_row(params)
    b = table_row(with_options(params, shear="thesis"))
    assert np.array_equal(a[L.N_PARAM:], b[L.N_PARAM:])
    c = table_row(dataclasses.replace(params, compaction_b=2 * params.compaction_b))
    assert not np.array_equal(a[L.N_PARAM:], c[L.N_PARAM:])


def test_bucket_lookup_finds_the_same_interval_as_a_search():
    """The O(1) knot lookup (bucket map + at most one step) against numpy's searchsorted,
    on random points, the knots themselves and just beside them; outside → −1."""
    import numba

    from wovenimpact.kernels.fabric_table import knot_interval

    row = table_row(reference_fabric())
    kw, _ = FT.table_knots(row)
    nw, nf, s = len(kw), int(row[L.P_TAB_NF]), int(row[L.P_TAB_START])
    table = row.reshape(1, -1)

    @numba.njit
    def lookup(p, xs, out):
        for q in range(xs.shape[0]):
            out[q] = knot_interval(p, 0, s, nw, s + nw + nf, int(p[0, L.P_TAB_NBW]),
                                   p[0, L.P_TAB_IBW], xs[q])

    rng = np.random.default_rng(0)
    xs = np.concatenate([rng.uniform(kw[0], kw[-1], 20_000), kw, np.nextafter(kw, 0.0),
                         np.nextafter(kw, 2.0)])
    xs = xs[(xs >= kw[0]) & (xs <= kw[-1])]
    got = np.empty(xs.size, dtype=np.int64)
    lookup(table, xs, got)
    expect = np.clip(np.searchsorted(kw, xs, side="right") - 1, 0, nw - 2)
    assert np.array_equal(got, expect)
    out = np.empty(3, dtype=np.int64)
    lookup(table, np.array([kw[0] - 1e-9, kw[-1] + 1e-9, np.nan]), out)
    assert np.all(out == -1)


def test_tables_are_kept_on_disk_and_read_back_bitwise(tmp_path, monkeypatch):
    """A table built once is stored under the cache directory and the next process reads
    it (here: the uncached builder, with tabulation made to fail) bit for bit; a damaged
    file is rebuilt; another material gets another file; WOVENIMPACT_TABLE_CACHE=0 keeps
    none."""
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    monkeypatch.setenv("WOVENIMPACT_TABLE_CACHE", "1")  # tests/conftest.py turns it off
    params = FT._options_free(reference_fabric())
    build = FT._cached_table.__wrapped__  # the builder without this process's memory
    built = build(params)
    files = list((tmp_path / "wovenimpact" / "tables").glob("*.npz"))
    assert [f.stem for f in files] == [FT.table_key(params)]

    def no_build(*args):
        raise AssertionError("the table was rebuilt instead of read")

    with monkeypatch.context() as m:
        m.setattr(FT, "tabulate", no_build)
        again = build(params)
    assert np.array_equal(again, built) and again.tobytes() == built.tobytes()

    files[0].write_bytes(b"not a table")  # damaged: rebuilt and stored again
    assert build(params).tobytes() == built.tobytes()
    assert FT._read_table(files[0], FT.table_key(params)) is not None

    stiffer = dataclasses.replace(
        params, warp=dataclasses.replace(params.warp, modulus=1.1 * params.warp.modulus))
    assert FT.table_key(stiffer) != FT.table_key(params)

    monkeypatch.setenv("WOVENIMPACT_TABLE_CACHE", "0")
    assert FT.table_cache_dir() is None
    files[0].unlink()
    build(params)
    assert not files[0].exists()


def test_the_table_cache_keeps_the_most_recently_used(tmp_path, monkeypatch):
    """Past TABLE_CACHE_FILES tables the least recently used file goes; a table read is
    used."""
    monkeypatch.setattr(FT, "TABLE_CACHE_FILES", 2)
    row = FT._cached_table(FT._options_free(reference_fabric()))
    paths = [tmp_path / f"k{i}.npz" for i in range(3)]
    for i, path in enumerate(paths[:2]):
        FT._write_table(path, f"k{i}", row)
        os.utime(path, (1000.0 + i, 1000.0 + i))
    assert FT._read_table(paths[0], "k0") is not None  # k0 is now the most recent
    FT._write_table(paths[2], "k2", row)
    assert sorted(p.name for p in tmp_path.glob("*.npz")) == ["k0.npz", "k2.npz"]
