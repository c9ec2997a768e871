"""Bad input to the sweep commands, each a one-line error naming its argument (docs/sweeps.md).

The scheduler address (schemes, malformed addresses, peers that are TCP services but not dask
schedulers, served by a small socket server in this process), a store whose fingerprint or
arrays were changed, numbers of thousands of digits in ``--vary``/``--ratios``/``--friction``/
``--workers``, and the validation of a large sweep (fast to fail, with progress lines). No test
here starts a dask cluster.
"""
from __future__ import annotations

import socket
import struct
import threading
import time
import tracemalloc

import numpy as np
import pytest

pytest.importorskip("distributed")
zarr = pytest.importorskip("zarr")
pytest.importorskip("xarray")

import rollqp  # noqa: E402
import rollqp.sweep  # noqa: E402
from rollqp import cli  # noqa: E402
from rollqp.errors import InputError  # noqa: E402
from rollqp.sweep import build_sweep, prepare  # noqa: E402
from rollqp.sweep.dataset import FINGERPRINT, create_store  # noqa: E402
from rollqp.sweep.executor import HANDSHAKE_BYTES, check_scheduler, connect  # noqa: E402

SMALL = {"discretization.elements": 20, "discretization.distance": 2.0}
HUGE = "1" * 5000  # more digits than Python converts to an int (4,300)


def _small():
    return rollqp.load_scene("cattaneo-carter").replace(**SMALL)


class _Peer:
    """A TCP server on 127.0.0.1 that answers every connection with ``payload`` and then holds it
    open for ``hold`` seconds (a service that is not a dask scheduler)."""

    def __init__(self, payload: bytes, hold: float = 3.0):
        self.payload, self.hold = payload, hold
        self.sock = socket.socket()
        self.sock.bind(("127.0.0.1", 0))
        self.sock.listen(8)
        self.sock.settimeout(0.2)
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._serve, daemon=True)
        self.thread.start()

    @property
    def address(self) -> str:
        return f"tcp://127.0.0.1:{self.sock.getsockname()[1]}"

    def _serve(self):
        deadline = time.monotonic() + 30  # bounded: the server stops by itself
        while not self.stop.is_set() and time.monotonic() < deadline:
            try:
                conn, _ = self.sock.accept()
            except OSError:
                continue
            with conn:
                try:
                    conn.sendall(self.payload)
                except OSError:
                    continue
                self.stop.wait(self.hold)

    def close(self):
        self.stop.set()
        self.thread.join(5)
        self.sock.close()


@pytest.fixture
def peer(request):
    p = _Peer(request.param)
    yield p
    p.close()


PEERS = {
    "ssh-banner": b"SSH-2.0-OpenSSH_9.6p1 Ubuntu-3ubuntu13\r\n",
    "http": b"HTTP/1.1 400 Bad Request\r\nContent-Length: 0\r\n\r\n",
    "huge-length": struct.pack("<Q", 2**62) + b"\0" * 64,
    # a length a machine could allocate (64 MiB): refused by the cap, not by a failed allocation
    "crafted-length": struct.pack("<Q", 64 * 2**20) + b"\0" * 64,
    "garbage-frame": struct.pack("<Q", 32) + bytes(range(32)),
    "silent": b"",
}


@pytest.mark.parametrize("peer", list(PEERS.values()), ids=list(PEERS), indirect=True)
def test_a_peer_that_is_not_a_dask_scheduler_is_a_one_line_error_in_bounded_time_and_memory(peer):
    tracemalloc.start()
    t0 = time.perf_counter()
    try:
        with pytest.raises(InputError, match=r"^--scheduler: 'tcp://127\.0\.0\.1:\d+': not a dask scheduler: ") as err:
            connect(peer.address, timeout=1.0)
        elapsed = time.perf_counter() - t0
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert "\n" not in str(err.value)
    assert elapsed < 3.0  # the 1 s timeout for the silent peer; the others are refused on their first bytes
    # nothing sized by the peer: the probe reads at most HANDSHAKE_BYTES (numpy and Python
    # allocations are both traced; dask's reader would have asked for the announced length)
    assert peak < 4 * HANDSHAKE_BYTES + 2**20, peak


@pytest.mark.parametrize("peer", [PEERS["ssh-banner"]], ids=["ssh-banner"], indirect=True)
def test_cli_with_a_peer_that_is_not_a_scheduler_exits_2_with_one_line_and_writes_nothing(peer, capsys, tmp_path,
                                                                                          monkeypatch):
    monkeypatch.chdir(tmp_path)
    code = cli.main(["sweep", "cattaneo-carter", "--vary", "contact.friction=0.1,0.2", "--out", "s.zarr",
                     "--scheduler", peer.address])
    err = capsys.readouterr().err
    assert code == cli.EXIT_INPUT and err.count("\n") == 1 and "--scheduler" in err and "announces" in err
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("address, match", [
    ("ucx://127.0.0.1:8786", r"the scheme ucx:// is not supported"),
    ("tls://127.0.0.1:8786", r"tls:// needs a dask TLS configuration"),
    ("ws://127.0.0.1:8786", r"the scheme ws:// is not supported"),
    ("tcp://127.0.0.1:99999", r"a port in \[1, 65535\]"),
    ("tcp://:8786", r"needs a host"),
    ("tcp://127.0.0.1", r"not HOST:PORT"),
    ("tcp://127.0.0.1:8786 ; rm -rf /", r"not an address such as tcp://HOST:8786"),
    ("tcp://" + "a" * 2000 + ":1", r"… \(\d+ characters\): not an address"),
    ("inproc://192.0.2.1/1/1", r"no scheduler of this process listens there"),
])
def test_scheduler_address_is_checked_before_any_connection(address, match):
    t0 = time.perf_counter()
    with pytest.raises(InputError, match=r"^--scheduler: .*" + match) as err:
        check_scheduler(address, timeout=1.0)
    assert "\n" not in str(err.value) and len(str(err.value)) < 300
    assert time.perf_counter() - t0 < 1.0  # no connection attempted, no timeout waited for


def test_unreachable_scheduler_is_a_one_line_error_within_the_timeout():
    t0 = time.perf_counter()
    with pytest.raises(InputError, match=r"--scheduler: cannot reach a dask scheduler at 'tcp://127.0.0.1:9' within 1 s"):
        connect("tcp://127.0.0.1:9", timeout=1.0)
    assert time.perf_counter() - t0 < 5
    for bad in (-1, 1000, 2.0, True, 10**5000):
        with pytest.raises(InputError, match=r"--workers: must be an integer in \[0, ") as err:
            connect(workers=bad)
        assert len(str(err.value)) < 200
    with pytest.raises(InputError, match="--workers: applies to the local cluster only"):
        connect("tcp://127.0.0.1:9", workers=2)


# --------------------------------------------------------------------------- the store
def _tamper(store, **attrs):
    group = zarr.open_group(str(store), mode="r+", use_consolidated=False)
    group.attrs.update(attrs)
    zarr.consolidate_metadata(str(store))


@pytest.mark.parametrize("value, kind", [(12345, "int"), (["a"], "list"), ("ab" * 10, "str"), (None, None)])
def test_store_with_a_fingerprint_of_the_wrong_type_is_refused_in_one_line(tmp_path, value, kind):
    vary = ["contact.friction=0.1,0.2"]
    store = tmp_path / "s.zarr"
    create_store(str(store), build_sweep(_small(), vary))
    _tamper(store, **{FINGERPRINT: value})
    match = r"no fingerprint" if value is None else rf"its {FINGERPRINT} attribute is {kind} .*not a SHA-256"
    with pytest.raises(InputError, match=r"^--out: .*" + match) as err:
        prepare(_small(), vary, store)
    assert "\n" not in str(err.value)


def test_store_whose_arrays_were_changed_is_refused_in_one_line(tmp_path):
    vary = ["contact.friction=0.1,0.2"]
    store = tmp_path / "s.zarr"
    create_store(str(store), build_sweep(_small(), vary))
    group = zarr.open_group(str(store), mode="r+", use_consolidated=False)
    del group["status"]
    zarr.consolidate_metadata(str(store))
    with pytest.raises(InputError, match=r"^--out: .*array 'status' is missing"):
        prepare(_small(), vary, store)
    store2 = tmp_path / "t.zarr"
    create_store(str(store2), build_sweep(_small(), vary))
    group = zarr.open_group(str(store2), mode="r+", use_consolidated=False)
    group["status"][...] = np.array([1, 7], dtype="int8")
    with pytest.raises(InputError, match=r"^--out: .*status variable holds values other than 0, 1, 2"):
        prepare(_small(), vary, store2)


# --------------------------------------------------------------------------- numbers and counts
def _exit_code(argv) -> int:
    """``rollqp ARGV``'s exit code (argparse's own errors exit through SystemExit)."""
    try:
        return cli.main(argv)
    except SystemExit as stop:
        return stop.code

@pytest.mark.parametrize("argv, name", [
    (["sweep", "cattaneo-carter", "--vary", f"contact.friction={HUGE}"], "--vary"),
    (["sweep", "cattaneo-carter", "--vary", f"contact.friction=0.1,{HUGE}"], "--vary"),
    (["sweep", "cattaneo-carter", "--vary", f"discretization.elements=10:20:{HUGE}"], "--vary"),
    (["sweep", "cattaneo-carter", "--vary", f"discretization.elements={HUGE}:20:3"], "--vary"),
    (["sweep", "cattaneo-carter", "--vary", "contact.friction=0.1", "--workers", HUGE], "--workers"),
    (["creep-curve", "cattaneo-carter", f"--ratios={HUGE}"], "--ratios"),
    (["creep-curve", "cattaneo-carter", f"--ratios=0.1,-{HUGE}"], "--ratios"),
    (["creep-curve", "cattaneo-carter", f"--friction={HUGE}"], "--friction"),
    (["creep-curve", "cattaneo-carter", f"--friction=0.1:0.2:{HUGE}"], "--friction"),
])
def test_numbers_of_thousands_of_digits_are_one_line_errors(argv, name, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert _exit_code(argv) == cli.EXIT_INPUT
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and name in err and len(err) < 400, err[:400]
    assert "Traceback" not in err and not list(tmp_path.iterdir())


def test_creep_curve_arguments_name_themselves(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    for argv, match in ((["--ratios", "0.5,abc"], "--ratios: 0.5,abc: mixes numbers and words"),
                        (["--ratios", "0.5,1.2"], "--ratios: load ratios Q/(mu P) must be numbers in (-1, 1)"),
                        (["--ratios=-1:0.5:4"], "--ratios: load ratios"),
                        (["--friction", "0,0.1"], "--friction: friction coefficients must be finite numbers > 0"),
                        (["--friction", "0.1,0.1"], "--friction: 0.1,0.1: repeated values")):
        assert cli.main(["creep-curve", "cattaneo-carter", *argv]) == cli.EXIT_INPUT
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and match in err, err
    from rollqp.sweep.creep import creep_sweep
    for bad in ([0.5, float("nan")], [10**400], ["0.5"], [True], []):
        with pytest.raises(InputError, match="--ratios: load ratios"):
            creep_sweep(_small(), bad)
    assert not list(tmp_path.iterdir())


# --------------------------------------------------------------------------- large sweeps
def test_a_bad_value_at_the_end_of_a_large_sweep_is_found_at_once():
    """100,000 points whose bad friction value (-1) comes last in product order: the
    validation meets every value of every key within the first 1,000 points, so it stops in
    about a second, naming that point, instead of after ~10^5 scene validations."""
    frictions = ",".join(f"{0.1 + 1e-4 * i:.4f}" for i in range(999)) + ",-1"
    t0 = time.perf_counter()
    with pytest.raises(InputError, match=r"^--vary: point \d+ \(contact\.friction=-1, load\.tangential=") as err:
        build_sweep(_small(), [f"contact.friction={frictions}", "load.tangential=0.1:0.8:100"])
    assert time.perf_counter() - t0 < 30  # ~1,000 validations (~0.5 s); the product order would take ~50 s
    assert "\n" not in str(err.value)


def test_validation_of_many_points_shows_progress_lines(capsys, tmp_path, monkeypatch):
    monkeypatch.setattr(rollqp.sweep, "VALIDATION_PROGRESS_AFTER", 0.0)
    monkeypatch.setenv("ROLLQP_PROGRESS_SECONDS", "0.05")
    sw, _ = prepare(_small(), ["contact.friction=0.1:0.3:30", "load.tangential=0.1:0.8:20"], tmp_path / "s.zarr",
                    quiet=False)
    lines = capsys.readouterr().err.splitlines()
    assert sw.size == 600 and len(sw.scenes) == 600
    assert lines and all(ln.startswith("rollqp: validated point ") for ln in lines), lines
    assert lines[-1].startswith("rollqp: validated point 600/600 (100 %)")
    prepare(_small(), ["contact.friction=0.1:0.3:30"], tmp_path / "s.zarr", quiet=True)
    assert capsys.readouterr().err == ""


def test_sweep_scenes_are_built_on_demand_and_equal_replace():
    sw = build_sweep(_small(), ["contact.friction=0.1,0.2,0.3", "solver.method=newton,qp-osqp"])
    assert len(sw.scenes) == 6 and sw.scenes[5] == _small().replace(**{"contact.friction": 0.3,
                                                                         "solver.method": "qp-osqp"})
    assert sw.scenes[-1] == sw.scenes[5] and [s.contact.friction for s in sw.scenes][::2] == [0.1, 0.2, 0.3]
    with pytest.raises(IndexError):
        sw.scenes[6]
    assert sw.facts.states.shape == (6,) and len(sw.facts.q) == 1 and len(sw.facts.x) == 1


# --------------------------------------------------------------------------- in this process
def test_workers_0_runs_the_points_in_this_process_into_the_same_store(tmp_path):
    """``--workers 0``: no cluster and no dask; the points one after another in this process,
    written as a cluster's would be (several points per chunk), each bitwise equal to its scene
    run alone, resumable the same way."""
    from rollqp.sweep import sweep
    vary = ["contact.friction=0.1,0.2,0.3", "load.tangential=0.2,0.6"]
    base = _small().replace(**{"discretization.distance": 1.0})
    store = tmp_path / "p.zarr"
    summary = sweep(base, vary, store, workers=0)
    assert summary.done == 6 and summary.workers == 0 and summary.per_chunk == 2 and "none, this process" in summary.table()
    xr = pytest.importorskip("xarray")
    ds = xr.open_zarr(store, chunks=None).load()
    sw = build_sweep(base, vary)
    for i in range(6):
        alone = rollqp.run(sw.scenes[i]).arrays()
        point = ds.sel(dict(zip(sw.keys, (ds[k].values[j] for k, j in zip(sw.keys, sw.index(i))))))
        for name in ("pn", "pt", "creepage", "Q", "iterations"):
            got = point[name].values[tuple(slice(0, n) for n in np.shape(alone[name]))]
            np.testing.assert_array_equal(got, alone[name])  # bitwise: the same code, one BLAS thread
    again = sweep(base, vary, store, workers=0)
    assert again.kept == 6 and again.done == 0


def test_workers_0_imports_no_dask(tmp_path):
    import subprocess
    import sys
    code = ("import sys; from rollqp import cli; "
            "rc = cli.main(['sweep', 'cattaneo-carter', '--vary', 'contact.friction=0.1,0.2', '--vary', "
            "'discretization.distance=0.5', '--out', 's.zarr', '--workers', '0', '--quiet']); "
            "print(rc, 'distributed' in sys.modules, 'dask' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path, timeout=120)
    assert out.stdout.split() == ["0", "False", "False"], out.stderr[-2000:]


def test_a_task_that_cannot_write_its_chunk_sends_its_arrays_instead(tmp_path):
    """A worker that shares no disk with the store (here: a store path that is not one) keeps each
    point's arrays in its answer, unmarked, so that the client writes them; one it can write marks
    them written and sends none."""
    from rollqp.sweep.executor import compute_points
    base = _small().replace(**{"discretization.distance": 1.0})
    sw = build_sweep(base, ["contact.friction=0.1,0.2"])
    points = [(i, sw.changes(i)) for i in range(2)]
    missing = (str(tmp_path / "nowhere.zarr"), sw.fingerprint(), sw.keys, sw.shape)
    outs = compute_points(base.to_dict(), points, missing)
    assert [o.get("written") for o in outs] == [None, None] and all("arrays" in o for o in outs)
    store = tmp_path / "s.zarr"
    create_store(store, sw, 2)
    outs = compute_points(base.to_dict(), points, (str(store), sw.fingerprint(), sw.keys, sw.shape))
    assert all(o["written"] and "arrays" not in o for o in outs)
    xr = pytest.importorskip("xarray")
    ds = xr.open_zarr(store, chunks=None).load()
    assert np.all(ds["status"].values == 1)
    alone = rollqp.run(sw.scenes[1]).arrays()
    np.testing.assert_array_equal(ds["pt"].values[1][:alone["pt"].shape[0], :alone["pt"].shape[1]], alone["pt"])


# --------------------------------------------------------------------------- the store's files
def _files(root) -> dict:
    """``key -> bytes`` of every file under ``root`` (keys ``/``-separated)."""
    import os
    out = {}
    for folder, _, names in os.walk(root):
        for name in names:
            path = os.path.join(folder, name)
            with open(path, "rb") as fh:
                out[os.path.relpath(path, root).replace(os.sep, "/")] = fh.read()
    return out


STORES = [  # (vary, points per chunk): numeric axes; a word axis with a swept mesh (2-D q and x);
    (["contact.friction=0.1,0.2,0.3"], 2),  # chunks that do not tile the grid (padded edge chunks)
    (["discretization.elements=20,40,60", "solver.method=newton,qp-osqp"], 4),
    (["discretization.step=0.25,0.5", "contact.friction=0.1:0.3:3"], 5),
]


@pytest.mark.parametrize("vary, per_chunk", STORES)
def test_a_store_written_directly_has_zarrs_files(tmp_path, vary, per_chunk):
    """The metadata and coordinate chunks written by create_store itself are zarr's own: the same keys,
    the same JSON documents, the same chunk bytes (encoded with the same compressor), and xarray
    reads the same dataset from both."""
    import json

    import xarray as xr
    sw = build_sweep(_small().replace(**{"discretization.distance": 1.0}), vary)
    create_store(tmp_path / "direct.zarr", sw, per_chunk)
    create_store(tmp_path / "zarr.zarr", sw, per_chunk, direct=False)
    mine, theirs = _files(tmp_path / "direct.zarr"), _files(tmp_path / "zarr.zarr")
    assert sorted(mine) == sorted(theirs)
    assert {k for k in mine if not k.rsplit("/", 1)[-1].startswith(".")}  # coordinate chunks are compared too
    for key in mine:
        if key.rsplit("/", 1)[-1] in (".zarray", ".zattrs", ".zgroup", ".zmetadata"):
            assert json.loads(mine[key]) == json.loads(theirs[key]), key
        else:
            assert mine[key] == theirs[key], key
    a = xr.open_zarr(tmp_path / "direct.zarr", chunks=None).load()
    b = xr.open_zarr(tmp_path / "zarr.zarr", chunks=None).load()
    xr.testing.assert_identical(a, b)
    assert a.sizes[sw.keys[-1]] == sw.shape[-1] and a.attrs[FINGERPRINT] == sw.fingerprint()


def _outs(sw, points, fail=()):
    """Each point's result as a task returns it (``fail``: points given an error instead)."""
    from rollqp.sweep.executor import compute_points
    outs = compute_points(sw.base.to_dict(), [(i, sw.changes(i)) for i in points])
    for i, out in zip(points, outs):
        if i in fail:
            out.pop("arrays")
            out["error"] = "SolverError: made to fail here"
    return outs


def test_a_writer_from_the_files_writes_what_zarr_writes(tmp_path):
    """StoreWriter.at (the arrays known from .zmetadata, chunks written as files) and a writer through
    zarr (a store without consolidated metadata) store the same points alike, a chunk written again
    for one of its points (a resumed sweep's failed point) keeping the others."""
    import os

    import xarray as xr

    from rollqp.sweep.dataset import StoreWriter
    sw = build_sweep(_small().replace(**{"discretization.distance": 1.0}), ["contact.friction=0.1,0.2,0.3"])
    first, again = _outs(sw, [0, 1, 2], fail=(1,)), _outs(sw, [1])
    for name in ("files", "zarr"):
        create_store(tmp_path / f"{name}.zarr", sw, 2)
        if name == "zarr":
            os.remove(tmp_path / "zarr.zarr" / ".zmetadata")
            writer = StoreWriter(zarr.open_group(str(tmp_path / "zarr.zarr"), mode="r+", zarr_format=2), sw)
            assert not writer.on_disk
        else:
            writer = StoreWriter.at(tmp_path / "files.zarr", sw)
            assert writer.on_disk and writer.root == str(tmp_path / "files.zarr")
        writer.write([0, 1], first[:2])
        writer.write([2], first[2:])
        assert list(np.asarray(zarr.open_group(str(tmp_path / f"{name}.zarr"), mode="r")["status"])) == [1, 2, 1]
        writer.write([1], again)
    a = xr.open_zarr(tmp_path / "files.zarr", chunks=None, consolidated=True).load()
    b = xr.open_zarr(tmp_path / "zarr.zarr", chunks=None, consolidated=False).load()
    xr.testing.assert_identical(a.drop_vars("point_time"), b.drop_vars("point_time"))
    assert list(a["status"].values) == [1, 1, 1] and list(a["error"].values) == ["", "", ""]
    alone = rollqp.run(sw.scenes[1]).arrays()
    np.testing.assert_array_equal(a["pt"].values[1][:alone["pt"].shape[0], :alone["pt"].shape[1]], alone["pt"])
    np.testing.assert_array_equal(a["pt"].values[0], b["pt"].values[0])


def test_a_sweep_resumes_a_store_made_by_zarr(tmp_path):
    """A store whose files zarr wrote (create_store(..., direct=False)) is continued by a sweep like one
    of its own: the points already done kept, the others computed into it."""
    import xarray as xr

    from rollqp.sweep import sweep
    from rollqp.sweep.dataset import StoreWriter
    base = _small().replace(**{"discretization.distance": 1.0})
    vary = ["contact.friction=0.1,0.2,0.3,0.4"]
    sw = build_sweep(base, vary)
    store = tmp_path / "s.zarr"
    create_store(store, sw, 2, direct=False)
    StoreWriter.at(store, sw).write([0, 1], _outs(sw, [0, 1]))
    summary = sweep(base, vary, store, workers=0)
    assert summary.kept == 2 and summary.done == 2
    ds = xr.open_zarr(store, chunks=None).load()
    assert list(ds["status"].values) == [1, 1, 1, 1]
    for i in range(4):
        alone = rollqp.run(sw.scenes[i]).arrays()
        np.testing.assert_array_equal(ds["pn"].values[i][:alone["pn"].shape[0], :alone["pn"].shape[1]], alone["pn"])


def test_a_coordinate_of_another_type_is_written_by_zarr(tmp_path):
    """A swept key whose values are neither numbers nor words (booleans, possible through the Python
    API's Sweep) gets its store through zarr: the same files as create_store(..., direct=False)."""
    from rollqp.sweep import Axis, Sweep
    sw = build_sweep(_small(), ["contact.friction=0.1,0.2"])
    odd = Sweep(sw.base, (Axis("contact.friction", (True, False)),), sw.facts)
    create_store(tmp_path / "a.zarr", odd, 2)
    create_store(tmp_path / "b.zarr", odd, 2, direct=False)
    import json
    mine, theirs = _files(tmp_path / "a.zarr"), _files(tmp_path / "b.zarr")
    assert sorted(mine) == sorted(theirs) and "contact.friction/0" in mine
    for key in mine:
        meta = key.rsplit("/", 1)[-1].startswith(".")
        assert (json.loads(mine[key]) == json.loads(theirs[key])) if meta else mine[key] == theirs[key], key
    assert zarr.open_group(str(tmp_path / "a.zarr"), mode="r")["contact.friction"].dtype == np.dtype(bool)


def test_a_store_made_again_at_the_same_path_gets_a_writer_of_its_own(tmp_path):
    """A process that wrote into a store keeps its writer for the next tasks; a store deleted and made
    again at the same path with other chunks (the same sweep, another per_chunk) is written with its
    own chunks, not the first store's."""
    import shutil

    import xarray as xr

    from rollqp.sweep.executor import compute_points
    base = _small().replace(**{"discretization.distance": 1.0})
    sw = build_sweep(base, ["contact.friction=0.1,0.2"])
    store = tmp_path / "s.zarr"
    where = (str(store), sw.fingerprint(), sw.keys, sw.shape)
    create_store(store, sw, 2)
    assert all(o["written"] for o in compute_points(base.to_dict(), [(i, sw.changes(i)) for i in range(2)], where))
    shutil.rmtree(store)
    create_store(store, sw, 1)
    assert compute_points(base.to_dict(), [(1, sw.changes(1))], where)[0]["written"]
    ds = xr.open_zarr(store, chunks=None).load()
    assert ds["status"].encoding["chunks"] == (1,) and list(ds["status"].values) == [0, 1]
    alone = rollqp.run(sw.scenes[1]).arrays()
    np.testing.assert_array_equal(ds["pt"].values[1][:alone["pt"].shape[0], :alone["pt"].shape[1]], alone["pt"])
