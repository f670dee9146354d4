"""Benchmarks behind ``chargedesign bench``: one module per area, each with
``run(quick: bool) -> list[BenchTable]``. Every table reports ratios to a baseline
measured in the same run."""
