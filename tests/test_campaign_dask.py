"""Campaigns on a dask.distributed cluster (issue 16): a LocalCluster of 2 worker processes
× 1 thread runs run_campaign's tasks, through the Client itself and through
client.get_executor(), with results bitwise those of the local run (the oracle: the same
campaign run in this process), a progress bar advanced by the cluster's finished tasks, and
a store written by the client while the workers compute."""
from __future__ import annotations

import re

import pytest

from specdesign import simulate as sm
from specdesign import turbine
from specdesign.validate import run_campaign

from test_campaign_store import assert_bitwise_equal

distributed = pytest.importorskip("distributed")
pytestmark = pytest.mark.slow  # a cluster of 2 spawned workers: ~40 s

SPEEDS = [15.0, 17.0, 19.0]
KW = dict(duration=30.0, transient=5.0)


@pytest.fixture(scope="module")
def client():
    # processes (spawned, as distributed does by default): numba's threads make fork unsafe
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        with distributed.Client(cluster) as c:
            yield c


@pytest.fixture(scope="module")
def setup():
    model = turbine.iea15mw()
    ctrls = {"ROSCO": sm.rosco_scheduled(model), "PI19": turbine.rosco_baseline(model, 19.0)}
    local = run_campaign(ctrls, SPEEDS, 2, model=model, keep_series=1, progress=False, **KW)
    return model, ctrls, local


def test_campaign_on_a_local_cluster_is_bitwise_the_local_run(client, setup, capsys):
    model, ctrls, local = setup
    with distributed.get_task_stream(client) as stream:
        on_cluster = run_campaign(ctrls, SPEEDS, 2, model=model, keep_series=1, executor=client, progress=True, **KW)
    assert_bitwise_equal(on_cluster, local)
    # one task per wind speed, run by the cluster's workers, not here
    assert len(stream.data) == len(SPEEDS)
    assert {t["worker"] for t in stream.data} <= set(client.scheduler_info()["workers"])
    # the bar counted every run (3 speeds × 2 seeds × 2 controllers) as the cluster finished them
    bar = capsys.readouterr().err
    assert re.search(r"12/12 \[", bar) and "run" in bar


def test_campaign_through_the_client_executor_with_a_store(client, setup, tmp_path):
    model, ctrls, local = setup
    store = tmp_path / "cluster_store"
    with client.get_executor() as ex:
        on_cluster = run_campaign(ctrls, SPEEDS, 2, model=model, keep_series=1, executor=ex, store=store,
                                  progress=False, **KW)
    assert_bitwise_equal(on_cluster, local)
    assert len(list(store.glob("cells/*.nc"))) == 12
    # read back from the store without the cluster: nothing is left to run
    assert_bitwise_equal(run_campaign(ctrls, SPEEDS, 2, model=model, keep_series=1, store=store, progress=False,
                                      **KW), local)


def test_the_same_campaign_twice_on_the_client(client, setup):
    # the Client's futures are keyed by their arguments: the second, identical campaign gets
    # the same task keys right after the first one released them
    model, ctrls, local = setup
    for _ in range(2):
        again = run_campaign(ctrls, SPEEDS, 2, model=model, keep_series=1, executor=client, progress=False, **KW)
        assert_bitwise_equal(again, local)


def _every_core_blas():
    """Run on a worker: BLAS on every core (what it takes without dask's OPENBLAS_NUM_THREADS=1)."""
    import os

    from threadpoolctl import threadpool_info, threadpool_limits

    threadpool_limits(limits=os.cpu_count(), user_api="blas")  # stays set: not used as a context
    return max(lib["num_threads"] for lib in threadpool_info() if lib["user_api"] == "blas")


def test_bitwise_whatever_blas_threads_the_workers_start_with(client, setup):
    # dask starts workers with OPENBLAS/OMP/MKL_NUM_THREADS=1 (distributed.nanny.pre-spawn-environ);
    # here the workers' BLAS is set to every core, as a local run has it by default. Every task
    # runs BLAS on one thread itself (campaign_point), so neither the workers' thread count nor
    # the client's changes a bit.
    import os

    from threadpoolctl import threadpool_limits

    model, ctrls, local = setup
    threads = client.run(_every_core_blas)
    assert all(n == os.cpu_count() for n in threads.values()), threads
    try:
        on_cluster = run_campaign(ctrls, SPEEDS, 2, model=model, keep_series=1, executor=client, progress=False, **KW)
    finally:  # the module's other tests keep dask's default
        client.run(lambda: __import__("threadpoolctl").threadpool_limits(limits=1, user_api="blas") and None)
    assert_bitwise_equal(on_cluster, local)
    with threadpool_limits(limits=2, user_api="blas"):  # the client with two BLAS threads asked for
        assert_bitwise_equal(run_campaign(ctrls, SPEEDS, 2, model=model, keep_series=1, progress=False, **KW), local)
