"""virtual_world.core.arrays: a message's tuples as numpy arrays, the same bits as numpy's own
conversion, or None for what is not a flat sequence of plain numbers."""
import numpy as np

from virtual_world.core import arrays
from virtual_world.core.arrays import flat_float64, float64_array, uint32_array


def test_floats_convert_to_numpys_own_bits_signed_zeros_and_ints_included():
    values = (0.1, -0.0, 1e-320, 2.0 ** 60 + 1, 7, True, float("inf"), float("nan"), -3.5)
    converted = float64_array(values)
    expected = np.asarray(values, dtype=float)
    assert converted.dtype == np.float64
    assert converted.tobytes() == expected.tobytes()


def test_indices_convert_to_uint32_and_other_values_are_left_to_the_caller():
    np.testing.assert_array_equal(uint32_array((0, 5, 2 ** 32 - 1)), [0, 5, 2 ** 32 - 1])
    assert uint32_array((0, 5, 2 ** 32 - 1)).dtype == np.uint32
    for values in ((0, -1), (0, 2 ** 32), (0, 1.0), (0, "1"), ((0, 1), (2, 3))):
        assert uint32_array(values) is None, values
    for values in ((1.0, "x"), ((1.0, 2.0),), np.zeros(3, np.float32), range(3), None):
        assert float64_array(values) is None, values
    for values in (np.zeros(3, np.int64), np.zeros(3, np.float64)):
        assert uint32_array(values) is None, values


def test_an_array_of_the_type_is_taken_flat_without_a_copy():
    """A numpy request's fields (odin_common.node.numpy_requests) arrive as arrays."""
    vertices = np.arange(12.0).reshape(4, 3)
    flat = float64_array(vertices)
    assert flat.shape == (12,) and np.shares_memory(flat, vertices)
    indices = np.arange(6, dtype=np.uint32).reshape(2, 3)
    assert uint32_array(indices).shape == (6,)
    assert np.shares_memory(uint32_array(indices), indices)


def test_flat_float64_falls_back_to_numpy_for_other_sequences():
    np.testing.assert_array_equal(flat_float64(np.arange(6.0).reshape(2, 3)), np.arange(6.0))
    np.testing.assert_array_equal(flat_float64((1, 2.5)), [1.0, 2.5])


def test_a_tuple_converts_once_read_only_and_a_list_every_time():
    values = tuple(float(v) for v in range(1000))
    first = float64_array(values)
    assert float64_array(values) is first
    assert not first.flags.writeable
    as_list = list(values)
    assert float64_array(as_list) is not float64_array(as_list)
    assert float64_array(as_list).flags.writeable


def test_the_arrays_kept_are_bounded_by_their_numbers(monkeypatch):
    monkeypatch.setattr(arrays, "KEPT_NUMBERS", 2500)
    monkeypatch.setattr(arrays, "_kept", arrays._Kept())
    held = [tuple(float(k + v) for v in range(1000)) for k in range(4)]
    converted = [float64_array(values) for values in held]
    assert arrays._kept.numbers <= 2500
    assert float64_array(held[0]) is not converted[0]      # fell out, converted again
    assert float64_array(held[3]) is converted[3]


def test_threads_converting_at_once_get_their_own_numbers(monkeypatch):
    """Two Cores may build at once: the kept arrays stay consistent under threads that
    convert, find and push out tuples all the time."""
    import threading
    monkeypatch.setattr(arrays, "KEPT_NUMBERS", 300)
    monkeypatch.setattr(arrays, "_kept", arrays._Kept())
    failures = []

    def work(seed: int) -> None:
        try:
            for k in range(300):
                values = tuple(float(seed * 10_000 + k + v) for v in range(50))
                for _ in range(2):
                    assert float64_array(values).tolist() == list(values)
        except Exception as error:  # handed to the test's thread
            failures.append(error)

    threads = [threading.Thread(target=work, args=(seed,)) for seed in range(4)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert not failures
    assert arrays._kept.numbers == sum(len(v) for v, _ in arrays._kept.arrays.values())
