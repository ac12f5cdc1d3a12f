"""How make test shares the tests between its two processes (tests/conftest.py): a file to a process, and every
test whose id names float32 to the one process that compiles the float32 kernels."""

from __future__ import annotations

from conftest import Float32Together


def scope(nodeid: str) -> str:
    return Float32Together._split_scope(object.__new__(Float32Together), nodeid)


def test_float32_tests_of_any_file_are_one_unit_and_the_rest_go_a_file_at_a_time() -> None:
    assert scope("tests/core/test_dtype.py::test_float32_keeps_every_per_weight_array") == "float32"
    assert scope("tests/test_bench.py::test_step_bytes[float32-td]") == "float32"
    assert scope("tests/test_bench.py::test_step_bytes[float64-td]") == "tests/test_bench.py"
    assert scope("tests/core/test_fast.py::TestFreeze::test_td") == "tests/core/test_fast.py"
