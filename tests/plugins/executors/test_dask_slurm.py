"""executor=dask_slurm: the batch script of the workers, checked without SLURM."""
import pytest

from pointatlas.errors import ConfigError
from pointatlas_executors.dask_slurm import DaskSlurmExecutor

pytest.importorskip("dask_jobqueue")


def test_job_script_carries_the_configured_resources():
    ex = DaskSlurmExecutor(queue="compute", account="proj42", cores=4, processes=2,
                           memory="8GiB", walltime="02:00:00",
                           job_extra_directives=["--qos=normal"],
                           job_script_prologue=["source /shared/venvs/pa/bin/activate"],
                           python="/shared/venvs/pa/bin/python")
    script = ex.job_script()
    lines = script.splitlines()
    assert lines[0].startswith("#!")
    for directive in ("#SBATCH -p compute", "#SBATCH -A proj42", "#SBATCH -n 1",
                      "#SBATCH --cpus-per-task=4", "#SBATCH --mem=8G", "#SBATCH -t 02:00:00",
                      "#SBATCH --qos=normal"):
        assert directive in lines, (directive, script)
    # two worker processes of 2 threads each, numba told so before the environment starts
    assert lines.index("export NUMBA_NUM_THREADS=2") < lines.index(
        "source /shared/venvs/pa/bin/activate")
    worker = lines[-1]
    assert worker.startswith("/shared/venvs/pa/bin/python -m distributed.cli.dask_worker tcp://")
    assert "--nworkers 2" in worker and "--nthreads 2" in worker and "--nanny" in worker


@pytest.mark.parametrize("settings,message", [
    ({"walltime": "2h"}, "executor.walltime='2h' is invalid"),
    ({"cores": 2, "processes": 4}, "executor.processes=4 is more than executor.cores=2"),
])
def test_settings_slurm_would_reject_are_refused_first(settings, message):
    with pytest.raises(ConfigError, match=message):
        DaskSlurmExecutor(**settings).check_config()


def test_command_line_refuses_a_bad_walltime_in_one_line(run_cli, tmp_path):
    r = run_cli("pointatlas", "executor=dask_slurm", "executor.walltime=2h",
                f"outputs_root={tmp_path}", cwd=tmp_path)
    assert r.returncode != 0 and "Traceback" not in r.stderr
    assert "executor.walltime='2h' is invalid" in r.stderr
    assert not list(tmp_path.rglob("results.nc"))


def test_without_slurm_the_run_stops_in_one_line(run_cli, tmp_path):
    """This machine has no sbatch: the run says so before any work (walltime read as text)."""
    import shutil

    if shutil.which("sbatch"):
        pytest.skip("SLURM is installed here")
    r = run_cli("pointatlas", "executor=dask_slurm", "executor.walltime=02:00:00",
                "source.n_points=500", f"outputs_root={tmp_path}", cwd=tmp_path)
    assert r.returncode != 0 and "Traceback" not in r.stderr
    assert "submits its workers with sbatch, which is not on the PATH" in r.stderr
