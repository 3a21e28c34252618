"""The table of benchmarks/README.md, generated from the results files that the
benchmarks write (``benchmarks/results/*.json``)::

    python benchmarks/table.py

rewrites the part of the README between :data:`measure.TABLE_BEGIN` and
:data:`measure.TABLE_END`. A benchmark does the same whenever it writes its results
file (:func:`measure.write_result`), so this is needed only after a results file was
edited or removed by hand; ``tests/test_benchmark_table.py`` fails when the two differ.
"""

from __future__ import annotations

from measure import README, ROOT, write_table


def main() -> int:
    changed = write_table()
    print(f"{README.relative_to(ROOT)}: table {'rewritten' if changed else 'unchanged'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
