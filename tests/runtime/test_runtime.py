"""The runtime's handling of Python's garbage collector during a run."""

import gc
import subprocess
import sys
import weakref

from fleetsim.runtime import Runtime


class _Cycle:
    def __init__(self) -> None:
        self.me = self


def test_a_run_leaves_the_start_up_heap_out_of_full_collections_until_shutdown():
    before = gc.get_freeze_count()
    rt = Runtime()
    rt.run(duration=0.1)
    assert gc.get_freeze_count() > before
    rt.shutdown()
    assert gc.get_freeze_count() == 0


def test_cycles_made_during_a_run_are_still_collected():
    made = []

    def tick() -> None:
        c = _Cycle()
        made.append(weakref.ref(c))

    with Runtime() as rt:
        rt.create_timer(0.01, tick)
        rt.run(duration=0.1)
        gc.collect()
        assert len(made) >= 5 and all(r() is None for r in made)


def test_cycles_made_before_a_run_are_freed_after_its_shutdown():
    c = _Cycle()
    ref = weakref.ref(c)
    rt = Runtime()
    rt.run(duration=0.01)  # c is alive now: frozen with the start-up heap
    del c
    gc.collect()
    assert ref() is not None  # frozen objects are not collected while the run lasts
    rt.shutdown()
    gc.collect()
    assert ref() is None


def test_what_a_run_never_shut_down_froze_is_freed_at_interpreter_exit():
    # frozen objects are skipped by the collections at exit too: extension types freed only as
    # cycles (OMPL's) made nanobind report leaks after a test session with unshut runtimes
    code = (
        "import os\n"
        "from fleetsim.runtime import Runtime\n"
        "class Cycle:\n"
        "    def __init__(self): self.me = self\n"
        "    def __del__(self, write=os.write): write(1, b'freed')\n"
        "c = Cycle()\n"
        "Runtime().run(duration=0.01)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, check=True).stdout
    assert out == b"freed"
