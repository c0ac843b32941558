"""A fork server for the tests' console-script runs (``run_cli`` in ``conftest.py``).

Every ``pointatlas`` run as a user types it spends about 4.5 s importing numpy, scipy,
scikit-learn, xarray, numba, Hydra and the installed plugins before any work; the test suite
makes about 300 such runs. This process imports all that once and then, for each request,
forks: the child is a fresh process (own pid, working directory, environment, argv, stdio,
exit status) that runs the console script's entry point exactly as the installed script
would, then runs the ``atexit`` handlers and exits with the script's status. Nothing is
run in this process itself, so no state passes from one run to the next except the
imported modules (whose import-time settings come from the same environment as a
subprocess's would: ``run_cli`` falls back to a real subprocess when a test changes any
other variable).

Protocol, one JSON object per line: the client writes ``{"cmd", "args", "cwd", "env",
"stdout", "stderr"}``; the server answers ``{"pid"}`` when the child starts and
``{"pid", "returncode"}`` when it ends (negative: killed by that signal, as in
``subprocess``).
"""
from __future__ import annotations

import json
import os
import sys

PRELOAD = ["numpy", "scipy.sparse", "scipy.sparse.linalg", "scipy.linalg", "scipy.spatial",
           "scipy.optimize", "scipy.ndimage", "sklearn.neighbors", "sklearn.decomposition",
           "sklearn.manifold", "xarray", "netCDF4", "cf_units", "numba", "hydra", "omegaconf",
           "matplotlib.pyplot", "pymetis", "pointatlas.cli", "pointatlas.runs_cli",
           "pointatlas.report_cli"]


def preload() -> dict:
    """Import the libraries and every installed plugin module, then forget what the
    registry discovered (a child discovers the installed plugins again, as a new process
    would). Returns the environment variables the imports set (netCDF4 sets
    ``HDF5_PLUGIN_PATH``), which each child sets again as its own imports would have."""
    import importlib

    before = dict(os.environ)
    for name in PRELOAD:
        importlib.import_module(name)
    from pointatlas import registry

    for family in registry.FAMILIES:
        try:
            registry.load_all(family)
        except Exception:  # a broken plugin is the child's to report, as a script would
            pass
    registry.refresh()
    return {k: v for k, v in os.environ.items() if before.get(k) != v}


def entry_point(cmd: str):
    from importlib.metadata import entry_points

    (ep,) = [ep for ep in entry_points(group="console_scripts") if ep.name == cmd]
    return ep.load()


def child(request: dict, preload_set: dict) -> None:
    """Become the console script: stdio, directory, environment, argv; never returns."""
    code = 1
    try:
        null = os.open(os.devnull, os.O_RDONLY)
        out = os.open(request["stdout"], os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
        err = os.open(request["stderr"], os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
        for fd, target in ((null, 0), (out, 1), (err, 2)):
            os.dup2(fd, target)
            os.close(fd)
        os.chdir(request["cwd"])
        os.environ.clear()
        os.environ.update(request["env"])
        for key, value in preload_set.items():
            os.environ.setdefault(key, value)
        sys.argv = [request["argv0"], *request["args"]]
        main = entry_point(request["cmd"])
        try:
            status = main()
            code = 0 if status is None else int(status) if isinstance(status, int) else 1
        except SystemExit as exc:
            if exc.code is None:
                code = 0
            elif isinstance(exc.code, int):
                code = exc.code
            else:
                print(exc.code, file=sys.stderr)
                code = 1
        except BaseException:
            import traceback

            traceback.print_exc()
            code = 1
        import atexit

        atexit._run_exitfuncs()
    except BaseException:  # set-up failed: say so on the child's stderr
        import traceback

        traceback.print_exc()
    finally:
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except Exception:
                pass
        os._exit(code & 0xFF)


def serve() -> None:
    preload_set = preload()
    reply = os.fdopen(os.dup(1), "w", buffering=1)
    os.dup2(os.open(os.devnull, os.O_WRONLY), 1)  # stray prints must not break the protocol
    print(json.dumps({"ready": True, "env": dict(os.environ), "preload_set": preload_set}), file=reply)
    for line in sys.stdin:
        request = json.loads(line)
        pid = os.fork()
        if pid == 0:
            child(request, preload_set)
        print(json.dumps({"pid": pid}), file=reply)
        _, status = os.waitpid(pid, 0)
        code = -os.WTERMSIG(status) if os.WIFSIGNALED(status) else os.WEXITSTATUS(status)
        print(json.dumps({"pid": pid, "returncode": code}), file=reply)


if __name__ == "__main__":
    serve()
