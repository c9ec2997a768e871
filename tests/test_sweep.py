"""Sweeps on a real dask.distributed cluster: points equal to the scenes run alone, several
points per task and per chunk of the store, a killed sweep process and a killed worker, the
creep curve against Carter (and where Carter's relative error is undefined), bad input.

One 2-worker ``LocalCluster`` (two single-threaded worker processes; not a mock, not the
synchronous scheduler) is shared by the module's tests (``client`` fixture): starting it costs
a few seconds, the sweeps themselves well under a second each. The bad input that needs no
cluster is in ``test_sweep_hardening.py``.
"""
from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("distributed")
xr = pytest.importorskip("xarray")
zarr = pytest.importorskip("zarr")

import rollqp  # noqa: E402
from rollqp import cli  # noqa: E402
from rollqp import closedforms as cf  # noqa: E402
from rollqp.errors import InputError  # noqa: E402
from rollqp.sweep import build_sweep, parse_vary, prepare, sweep  # noqa: E402
from rollqp.sweep.dataset import create_store, open_result  # noqa: E402
from rollqp.sweep.executor import close_client, connect  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
#: A §6.1.1 scene small enough for the fast suite: 20 quadratic elements, 2 a_H of rolling.
SMALL = {"discretization.elements": 20, "discretization.distance": 2.0}
#: Fields that are wall times: they differ between any two runs, so they are not compared.
TIMES = ("step_time",)


@pytest.fixture(scope="module")
def client():
    c = connect(workers=2)
    yield c
    cluster = c.cluster
    c.close()
    cluster.close()


def _small():
    return rollqp.load_scene("cattaneo-carter").replace(**SMALL)


def _assert_point_equals_run(ds, sw, i):
    """Every field of point ``i`` of the dataset equals the scene run alone in this process, bitwise."""
    alone = rollqp.run(sw.scenes[i]).arrays()
    sel = dict(zip(sw.keys, (ds[k].values[j] for k, j in zip(sw.keys, sw.index(i)))))
    point = ds.sel(sel)
    K1, n = alone["q"].size, alone["x"].size
    compared = 0
    for name, value in alone.items():
        if name in ("meta",) + TIMES:
            continue
        got = point[name].values
        got = got[tuple(slice(0, s) for s in np.shape(value))]
        # bitwise: the same code on the same inputs with one BLAS thread in both processes
        np.testing.assert_array_equal(got, value, err_msg=f"point {i} ({sw.label(i)}) field {name}")
        compared += 1
    assert compared >= 20
    # padding beyond the point's own states and nodes is NaN (not computed)
    assert np.all(np.isnan(point["pt"].values[K1:, :])) and np.all(np.isnan(point["pt"].values[:, n:]))


@pytest.mark.integration
def test_sweep_on_two_workers_equals_each_scene_run_alone(client, tmp_path):
    """Method × friction × mesh: 8 points on 2 worker processes, each bitwise equal to run(scene)."""
    store = tmp_path / "s.zarr"
    vary = ["solver.method=newton,qp-osqp", "contact.friction=0.1,0.3", "discretization.elements=10,20"]
    workers, sent = set(), []
    summary = sweep(_small(), vary, store, client=client,
                    on_point=lambda i, out: (workers.add(out["worker"]), sent.append(out)))
    assert summary.done == 8 and not summary.failed and summary.kept == 0
    assert len(workers) == 2, workers  # both worker processes computed points
    # a local cluster's workers share the client's disk: each wrote its own chunk, and sent back no arrays
    assert all(out.get("written") and "arrays" not in out for out in sent), sent
    sw = build_sweep(_small(), vary)
    ds = xr.open_zarr(store, chunks=None).load()
    assert ds.sizes["solver.method"] == 2 and ds.sizes["discretization.elements"] == 2
    assert list(ds["solver.method"].values) == ["newton", "qp-osqp"]
    assert ds["pt"].attrs["units"] == "force/length^2" and ds["pt"].attrs["long_name"]
    assert ds.attrs["rollqp_sweep_fingerprint"] == sw.fingerprint()
    assert np.all(ds["status"].values == 1)
    assert ds["x"].dims == ("solver.method", "contact.friction", "discretization.elements", "node")  # meshes differ
    for i in range(len(sw.scenes)):
        _assert_point_equals_run(ds, sw, i)


@pytest.mark.integration
def test_a_cluster_at_an_address_sends_its_points_and_the_client_writes_them(client, tmp_path):
    """Through ``--scheduler`` (a ``Client`` of an address, no shared disk assumed) the workers send the
    arrays and the client writes them: the same store, bitwise, as the local cluster's own writes."""
    import distributed
    vary = ["load.tangential=0.2,0.6", "contact.friction=0.1,0.3"]
    remote = distributed.Client(client.scheduler.address)
    try:
        sent = []
        summary = sweep(_small(), vary, tmp_path / "r.zarr", client=remote, on_point=lambda i, out: sent.append(out))
    finally:
        remote.close()
    assert summary.done == 4 and not summary.failed
    assert all(not out.get("written") and "arrays" in out for out in sent)
    local = sweep(_small(), vary, tmp_path / "l.zarr", client=client)
    assert local.done == 4
    a, b = (xr.open_zarr(tmp_path / f, chunks=None).load() for f in ("r.zarr", "l.zarr"))
    for name in a.data_vars:
        if name not in TIMES + ("point_time",):
            np.testing.assert_array_equal(a[name].values, b[name].values, err_msg=name)


def _status(store):
    try:
        return np.asarray(zarr.open_group(str(store), mode="r")["status"][...]).reshape(-1)
    except Exception:  # not created yet
        return None


@pytest.mark.integration
def test_killed_sweep_keeps_its_points_and_a_rerun_computes_only_the_rest(client, tmp_path):
    """SIGKILL the ``rollqp sweep`` process mid-sweep; the stored points stay and are not recomputed."""
    store = tmp_path / "k.zarr"
    vary = ["load.tangential=0.1:0.8:12"]
    # points of ~0.2 s (321 nodes, 3 a_H): the kill comes while most are still to do (the test polls every
    # 20 ms; twelve 41-node points, ~20 ms each, could all be stored before it)
    base = _small().replace(**{"discretization.elements": 160, "discretization.distance": 3.0})
    scene_file = tmp_path / "base.toml"
    scene_file.write_text(base.to_toml())
    env = dict(os.environ, PYTHONPATH=str(ROOT), OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    proc = subprocess.Popen([sys.executable, "-m", "rollqp.cli", "sweep", str(scene_file), "--vary", vary[0],
                             "--out", str(store), "--scheduler", client.scheduler.address, "--quiet"],
                            env=env, cwd=tmp_path, stderr=subprocess.PIPE)
    deadline = time.time() + 60
    while time.time() < deadline:
        st = _status(store)
        if st is not None and (st == 1).sum() >= 2 or proc.poll() is not None:
            break
        time.sleep(0.02)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert proc.returncode == -signal.SIGKILL, proc.stderr.read().decode()
    st = _status(store)
    done = set(np.flatnonzero(st == 1))
    assert 2 <= len(done) < 12, st  # killed mid-sweep: some points stored, some not
    before = xr.open_zarr(store, chunks=None).load()
    computed = []
    summary = sweep(scene_file, vary, store, client=client, on_point=lambda i, out: computed.append(i))
    assert summary.kept == len(done) and summary.done == 12 - len(done)
    assert set(computed) == set(range(12)) - done  # only the missing points ran
    after = xr.open_zarr(store, chunks=None).load()
    assert np.all(after["status"].values == 1)
    for i in done:  # untouched: a recomputed point would have new wall times
        for name in ("pt", "step_time", "point_time"):
            np.testing.assert_array_equal(after[name].values[i], before[name].values[i])
    sw = build_sweep(scene_file, vary)
    for i in (min(done), max(set(range(12)) - done)):
        _assert_point_equals_run(after, sw, i)


@pytest.mark.integration
def test_worker_killed_mid_sweep_loses_only_its_point_in_flight(client, tmp_path):
    """SIGKILL a busy worker process: its point is computed again elsewhere, every point ends equal."""
    store = tmp_path / "w.zarr"
    vary = ["load.tangential=0.2:0.7:6"]
    # points long enough (~0.2 s each: 321 nodes, 3 a_H) that the next ones are still in flight when the
    # sweep has written the first: with 41-node points (~20 ms) all six could be done by then
    base = _small().replace(**{"discretization.elements": 160, "discretization.distance": 3.0})
    pids = client.run(os.getpid)
    killed = []

    def kill_a_busy_worker(i, out):
        if killed:
            return
        busy = [w for w, tasks in client.processing().items() if tasks and w in pids]
        if busy:
            os.kill(pids[busy[0]], signal.SIGKILL)
            killed.append(busy[0])

    summary = sweep(base, vary, store, client=client, on_point=kill_a_busy_worker)
    assert killed, "no worker was busy after the first point"
    assert summary.done == 6 and not summary.failed
    ds = xr.open_zarr(store, chunks=None).load()
    sw = build_sweep(base, vary)
    for i in range(6):
        _assert_point_equals_run(ds, sw, i)
    client.wait_for_workers(2, timeout=60)  # the nanny restarts the killed worker for the next tests


@pytest.mark.integration
def test_creep_curve_converges_to_carter_at_first_order(client, tmp_path):
    """Q/μP = 0.05 … 0.95 on 40 and 80 quadratic elements: |ξ/ξ_Carter − 1| ≤ 0.25·Le/a_H (the
    documented creepage error is 5.8e-3 at 0.75 on 40 elements, docs/validation.md §5; measured
    max 0.21·Le/a_H over the ratios), halving as the mesh doubles (slope 1 ± 0.15), and dQ/dξ of
    the computed curve within 2 % of Carter's slope (finite differences on the 0.1 spacing)."""
    from rollqp.sweep.creep import creep_curve
    errors = {}
    for n in (40, 80):
        scene = rollqp.load_scene("cattaneo-carter").replace(**{"discretization.elements": n})
        curve = creep_curve(scene, "0.05:0.95:19", None, tmp_path / f"c{n}.zarr", client=client)
        assert curve.summary.done == 19 and not curve.summary.failed
        np.testing.assert_allclose(curve.ratio, np.linspace(0.05, 0.95, 19)[None, :], rtol=1e-12)
        err = np.abs(curve.xi / curve.carter_xi() - 1.0)
        le = 2.0 * scene.discretization.zone / n
        assert err.max() <= 0.25 * le, (n, err.max() / le)
        errors[n] = err
        slope = curve.slope()[0, 1:-1] / curve.carter_slope()[0, 1:-1] - 1.0
        assert np.abs(slope[:-2]).max() < 0.02, slope  # the last points: Carter's slope → 0 at saturation
    order = np.log2(errors[40] / errors[80])
    assert np.all(np.abs(order - 1.0) < 0.15), order
    path = curve.plot(tmp_path / "creep.png")
    assert Path(path).stat().st_size > 10_000


# --------------------------------------------------------------------------- no cluster needed
def test_open_result_is_the_npz_as_a_labelled_dataset(tmp_path):
    scene = _small()
    res = rollqp.run(scene)
    path = res.save(tmp_path / "r.npz")
    ds = rollqp.open_result(path)
    arrays = res.arrays()
    np.testing.assert_array_equal(ds["q"].values, arrays["q"])
    np.testing.assert_array_equal(ds["x"].values, arrays["x"])
    for name in ("pn", "pt", "slip", "state", "creepage", "a_H", "iterations"):
        np.testing.assert_array_equal(ds[name].values, arrays[name])
    assert ds["pn"].dims == ("step", "node") and ds["Q"].dims == ("step",)
    assert ds["pn"].attrs["units"] == "force/length^2" and "pressure" in ds["pn"].attrs["long_name"]
    assert ds.attrs["method"] == "newton" and '"friction": 0.1' in ds.attrs["scene"]
    with pytest.raises(InputError, match="RESULT.npz"):
        open_result(tmp_path / "missing.npz")


def test_vary_grammar():
    (a,) = parse_vary(["contact.friction=0.1:0.3:3"])
    np.testing.assert_allclose(a.values, (0.1, 0.2, 0.3), rtol=0, atol=1e-15)
    (b,) = parse_vary(["solver.tolerance=1e-12:1e-8:5:log"])
    assert b.values[0] == 1e-12 and b.values[-1] == 1e-8
    np.testing.assert_allclose(np.diff(np.log10(b.values)), 1.0)
    (c,) = parse_vary(["discretization.elements=10,20"])
    assert c.values == (10, 20) and all(isinstance(v, int) for v in c.values)
    (d,) = parse_vary(["solver.method=newton,qp-osqp"])
    assert d.values == ("newton", "qp-osqp")
    sw = build_sweep(_small(), ["load.tangential=0.25,0.5", "discretization.step=0.5,1"])
    assert sw.shape == (2, 2) and sw.scenes[3].load.tangential(0.0) == 0.5
    assert sw.scenes[3].discretization.step == 1.0 and sw.label(1) == "load.tangential=0.25, discretization.step=1"


@pytest.mark.parametrize("vary, match", [
    (["contact.fricton=0.1,0.2"], r"--vary: point 0 \(contact.fricton=0.1\): contact.fricton: unknown key; did you mean 'friction'"),
    (["contact.friction=0.1:0.2:0"], r"--vary: contact.friction=0.1:0.2:0: count must be an integer"),
    (["contact.friction=0.2:0.2:3"], r"empty range"),
    (["contact.friction="], r"no values"),
    (["contact.friction=0.1,,0.2"], r"empty value"),
    (["contact.friction=0.1,0.1"], r"repeated values"),
    (["contact.friction=0.1,abc"], r"mixes numbers and words"),
    (["contact.friction=-1:1:3:log"], r"log range needs start, stop > 0"),
    (["contact.friction=0.1,0.5,-1"], r"point 2 \(contact.friction=-1\): contact.friction: must be a number >= 0"),
    (["discretization.elements=10,20.5"], r"point 1 .*discretization.elements: must be an integer"),
    (["solver.method=newton,qp-foo"], r"point 1 \(solver.method=qp-foo\): solver.method"),
    (["contact.friction=0.1", "contact.friction=0.2"], r"contact.friction is given twice"),
    (["friction=0.1"], r"not KEY=VALUES with a dotted scene key"),
    (["contact.friction=1:2:3:lin"], r"a range is start:stop:count or start:stop:count:log"),
    (["discretization.elements=2:20000:10000", "contact.friction=0.1:0.2:20"], r"200000 points; at most 100000"),
])
def test_bad_vary_is_one_line_error_naming_it_before_any_work(vary, match, tmp_path):
    with pytest.raises(InputError, match=match) as err:
        prepare(_small(), vary, tmp_path / "s.zarr")
    assert "\n" not in str(err.value)
    assert not (tmp_path / "s.zarr").exists()


def test_store_of_another_sweep_is_refused_and_left_alone(tmp_path):
    store = tmp_path / "s.zarr"
    create_store(str(store), build_sweep(_small(), ["contact.friction=0.1,0.2"]))
    files = sorted(p.name for p in store.rglob("*"))
    for other in (["contact.friction=0.1,0.3"], ["load.tangential=0.1,0.2"]):
        with pytest.raises(InputError, match=r"--out: .* holds a different sweep"):
            prepare(_small(), other, store)
    with pytest.raises(InputError, match="holds a different sweep"):
        prepare(_small().replace(**{"contact.friction": 0.3}), ["discretization.step=0.5,1"], store)
    assert sorted(p.name for p in store.rglob("*")) == files
    (tmp_path / "plain.zarr").mkdir()
    with pytest.raises(InputError, match="not a rollqp sweep store"):
        prepare(_small(), ["contact.friction=0.1,0.2"], tmp_path / "plain.zarr")
    with pytest.raises(InputError, match=r"--out: a sweep store is a zarr folder ending in .zarr"):
        prepare(_small(), ["contact.friction=0.1,0.2"], tmp_path / "s.nc")


def test_cli_errors_are_one_line(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert cli.main(["sweep", "cattaneo-carter", "--vary", "contact.fricton=0.1"]) == cli.EXIT_INPUT
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "contact.fricton: unknown key" in err
    assert cli.main(["creep-curve", "cattaneo-carter", "--ratios", "0.5,1.2"]) == cli.EXIT_INPUT
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--ratios: load ratios Q/(mu P) must be numbers in (-1, 1)" in err
    assert cli.main(["creep-curve", "cattaneo-carter", "--friction", "0,0.1"]) == cli.EXIT_INPUT
    assert "--friction" in capsys.readouterr().err
    assert not list(tmp_path.iterdir())  # nothing written


@pytest.mark.integration
def test_failed_point_is_stored_with_its_error_and_tried_again_by_a_rerun(client, tmp_path):
    """A point whose solver fails (one Newton iteration allowed) is stored as failed with its
    one-line error; the other point is done; a re-run computes the failed point only."""
    store = tmp_path / "f.zarr"
    vary = ["solver.max_iterations=1,200"]
    summary = sweep(_small(), vary, store, client=client)
    assert summary.done == 1 and len(summary.failed) == 1
    label, message = summary.failed[0]
    assert label == "solver.max_iterations=1" and message.startswith("SolverError: step 0, newton")
    ds = xr.open_zarr(store, chunks=None)
    assert list(ds["status"].values) == [2, 1]
    assert ds["error"].values[0].startswith("SolverError: step 0") and ds["error"].values[1] == ""
    assert np.all(np.isnan(ds["pt"].values[0]))  # nothing stored for the failed point
    computed = []
    again = sweep(_small(), vary, store, client=client, on_point=lambda i, out: computed.append(i))
    assert again.kept == 1 and computed == [0] and len(again.failed) == 1


def test_several_points_per_task_are_written_as_one_chunk_and_equal_each_scene_run_alone(client, tmp_path):
    """24 points on 2 workers: ⌈√(24/2)⌉ = 4 points per task and per chunk of the store (a row of the
    last key), each point bitwise equal to its scene run alone; the store is read back as one dataset."""
    store = tmp_path / "c.zarr"
    vary = ["load.tangential=0.1:0.85:6", "contact.friction=0.1,0.15,0.2,0.3"]
    base = _small().replace(**{"discretization.distance": 1.0})
    summary = sweep(base, vary, store, client=client)
    assert summary.done == 24 and not summary.failed and summary.per_chunk == 4 and summary.workers == 2
    group = zarr.open_group(str(store), mode="r")
    assert group["status"].chunks == (1, 4) and group["pt"].chunks[:2] == (1, 4)
    assert group["pt"].chunks[2:] == group["pt"].shape[2:]  # every state and node of a point in its chunk
    ds = xr.open_zarr(store, chunks=None).load()
    sw = build_sweep(base, vary)
    assert np.all(ds["status"].values == 1) and np.all(ds["point_time"].values > 0)
    for i in (0, 3, 4, 14, 23):  # first and last of chunks, and the last point
        _assert_point_equals_run(ds, sw, i)


def test_rerun_of_a_chunk_with_a_failed_point_recomputes_it_alone_and_keeps_the_others(client, tmp_path):
    """Two points in one chunk, one fails: the re-run computes only the failed one and writes it
    into the chunk read back from the store; the other point keeps its bits (its wall times too)."""
    store = tmp_path / "f2.zarr"
    vary = ["solver.max_iterations=1,200"]
    first = sweep(_small(), vary, store, client=client, per_chunk=2)
    assert first.per_chunk == 2 and first.done == 1 and len(first.failed) == 1
    before = xr.open_zarr(store, chunks=None).load()
    computed = []
    again = sweep(_small(), vary, store, client=client, on_point=lambda i, out: computed.append(i))
    assert computed == [0] and again.kept == 1 and len(again.failed) == 1
    after = xr.open_zarr(store, chunks=None).load()
    for name in ("pt", "step_time", "point_time", "creepage"):
        np.testing.assert_array_equal(after[name].values[1], before[name].values[1])
    assert list(after["status"].values) == [2, 1] and after["error"].values[0].startswith("SolverError")
    assert after["point_time"].values[0] != before["point_time"].values[0]  # point 0 was run again


def test_creep_curve_through_zero_load_prints_no_nan(client, tmp_path):
    """Q/(μP) = 0 is free rolling (ξ = 0 for similar bodies): Carter's relative error is undefined
    there and shows as "—" with a note, as does the slope of a one-point curve; no "nan"."""
    from rollqp.sweep.creep import creep_curve
    scene = rollqp.load_scene("cattaneo-carter")
    curve = creep_curve(scene, "0,0.5", None, tmp_path / "z.zarr", client=client)
    assert curve.summary.done == 2 and abs(curve.xi[0, 0]) < 1e-12  # free rolling: no creepage (round-off)
    table = curve.table()
    assert "nan" not in table.lower() and "inf" not in table.lower()
    assert "| 0.1 | 0.0000 |" in table and "| — |" in table and "undefined where Carter's ξ is 0" in table
    one = creep_curve(scene, "0.3", None, tmp_path / "o.zarr", client=client).table()
    assert "nan" not in one.lower() and "no slope" in one
    bad = scene.replace(**{"solver.max_iterations": 1})
    failed = creep_curve(bad, "0.2,0.4", None, tmp_path / "b.zarr", client=client)
    assert len(failed.summary.failed) == 2
    assert "nan" not in failed.table().lower() and failed.table().count("failed") >= 2


def test_dashboard_port_in_use_gives_no_warning(recwarn):
    """Another program on 127.0.0.1:8787 (dask's dashboard port): the local cluster starts with
    no dashboard and its HTTP server on a port the system picks, so nothing is printed."""
    import warnings
    holder = socket.socket()
    try:
        holder.bind(("127.0.0.1", 8787))
        holder.listen(1)
    except OSError:  # already taken by another program: the case itself
        pass
    try:
        warnings.simplefilter("always")
        c = connect(workers=1)
        try:
            assert c.submit(int, "7").result() == 7
        finally:
            close_client(c)
    finally:
        holder.close()
    assert not [w for w in recwarn if "8787" in str(w.message) or "already in use" in str(w.message)]
