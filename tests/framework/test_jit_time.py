"""Stage timings leave numba's compilation out (it is recorded on its own)."""
import time

import numba
import numpy as np

from pointatlas.jit_time import StageTimer, compile_seconds


def test_compilation_is_counted_once_and_left_out_of_the_stage():
    compile_seconds()  # listening from here

    @numba.njit
    def inner(x):
        return x * 2.0

    @numba.njit
    def outer(a):  # compiling outer compiles inner: one outermost event
        s = 0.0
        for v in a:
            s += inner(v)
        return s

    times, compiles = {}, {}
    before = compile_seconds()
    with StageTimer(times, "stage", compiles):
        t0 = time.perf_counter()
        outer(np.arange(5.0))
        first_call = time.perf_counter() - t0
        time.sleep(0.05)
    compiled = compile_seconds() - before
    assert compiled > 0.05 and compiled <= first_call + 1e-3  # not counted twice
    assert compiles["stage"] == compiled
    assert 0.05 <= times["stage"] < 0.05 + (first_call - compiled) + 0.05
    with StageTimer(times, "again", compiles):  # compiled now: nothing to leave out
        outer(np.arange(5.0))
    assert compiles["again"] == 0.0
