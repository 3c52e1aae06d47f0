"""load_problem's work runs without Python's cycle collector, and leaves it as it was."""
import gc
import weakref

import pytest

from gui.cli import _without_cycle_collection


@pytest.mark.parametrize("enabled", [True, False])
def test_the_collector_is_off_in_the_block_and_as_before_after_it(enabled):
    was = gc.isenabled()
    (gc.enable if enabled else gc.disable)()
    try:
        with _without_cycle_collection():
            assert not gc.isenabled()
        assert gc.isenabled() is enabled
        with pytest.raises(KeyError):
            with _without_cycle_collection():
                raise KeyError("an error leaves the block as well")
        assert gc.isenabled() is enabled
    finally:
        (gc.enable if was else gc.disable)()


def test_what_the_block_made_is_old_and_its_cycles_are_still_freed():
    """Objects made in the block leave the young generation (no collection walks them at
    once when it ends); a cycle made there is freed by the next full collection."""
    class Node:
        pass

    with _without_cycle_collection():
        made = [[k] for k in range(5000)]
        cycle = Node()
        cycle.self = cycle
        freed = []
        watch = weakref.ref(cycle, lambda _: freed.append(True))
        del cycle
    assert gc.get_count()[0] < 1000
    gc.collect()
    assert freed and watch() is None
    assert len(made) == 5000
