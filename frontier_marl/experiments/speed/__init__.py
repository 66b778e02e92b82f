"""Speed benchmarks of the simulator and of training (docs/performance.md), each the code of a
script in benchmarks/ (``benchmarks/bench_*.py``); not tests: they run by hand."""
