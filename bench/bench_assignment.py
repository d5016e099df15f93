"""Hungarian assignment (SciPy) against a greedy baseline and brute force, at several table sizes.

Tables are shaped like the anchoring layer's: n percepts x n anchors, each percept with its true
anchor scored 0.65-0.98 and two look-alikes scored 0.3-0.8 (so a look-alike sometimes outscores
the truth), every other pair gated out. Hungarian is the project's ``assign`` (maximum-weight
matching over the pairs at or above 0.5); greedy takes the best remaining pair until none is left;
brute force tries every permutation (vectorised with NumPy; sizes up to 8). Figures: time per
table, and how many percepts each method gives to the wrong anchor. One thread. Nothing is asserted.

Run: python bench/bench_assignment.py [--quick] [--json PATH]
"""

# ruff: noqa: E402 - the thread limits must be set before NumPy is imported
from __future__ import annotations

import os

for variable in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[variable] = "1"

import itertools
import statistics

import numpy as np
from harness import script
from harness.results import BenchmarkResult, LinePlot, Table, median_seconds

from merlin2_sailor.anchoring.assignment import assign

THRESHOLD = 0.5
GATED = -1.0
LOOK_ALIKES = 2
BRUTE_FORCE_LIMIT = 8


def scored_table(size: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """A (size, size) table and, per percept, the column of its true anchor."""
    table = np.full((size, size), GATED)
    truth = rng.permutation(size)
    table[np.arange(size), truth] = rng.uniform(0.65, 0.98, size)
    for row in range(size):
        others = np.setdiff1d(np.arange(size), [truth[row]])
        confusers = rng.choice(others, size=min(LOOK_ALIKES, len(others)), replace=False)
        table[row, confusers] = rng.uniform(0.3, 0.8, len(confusers))
    return table, truth


def greedy(table: np.ndarray, threshold: float = THRESHOLD) -> np.ndarray:
    """(M, 2) matches: the best remaining acceptable pair first, until none is left."""
    rows, columns = np.nonzero(table >= threshold)
    order = np.argsort(-table[rows, columns], kind="stable")
    used_rows, used_columns, matches = set(), set(), []
    for row, column in zip(rows[order], columns[order], strict=True):
        if row not in used_rows and column not in used_columns:
            used_rows.add(row)
            used_columns.add(column)
            matches.append((row, column))
    return np.array(matches, dtype=np.intp).reshape(-1, 2)


def brute_force_weight(table: np.ndarray, threshold: float = THRESHOLD) -> float:
    """The largest total score of acceptable pairs over every permutation (square tables)."""
    weights = np.where(table >= threshold, table, 0.0)
    size = len(weights)
    permutations = np.array(list(itertools.permutations(range(size))), dtype=np.int8)
    return float(weights[np.arange(size), permutations].sum(axis=1).max())


def weight(table: np.ndarray, matches: np.ndarray) -> float:
    return float(table[matches[:, 0], matches[:, 1]].sum()) if len(matches) else 0.0


def wrong(matches: np.ndarray, truth: np.ndarray) -> int:
    """Percepts not given their true anchor (assigned elsewhere or left unmatched)."""
    correct = sum(1 for row, column in matches if truth[row] == column)
    return len(truth) - correct


def run(quick: bool = False) -> BenchmarkResult:
    rng = np.random.default_rng(0)
    sizes = (4, 8, 20, 100) if quick else (2, 4, 6, 8, 10, 20, 50, 100, 200)
    tables_per_size = 10 if quick else 50
    repeats = 3 if quick else 10
    result = BenchmarkResult(
        "assignment", "Hungarian assignment vs greedy and brute force",
        f"n x n score tables shaped like the anchoring layer's (a true anchor per percept plus {LOOK_ALIKES} "
        f"look-alikes, the rest gated), {tables_per_size} tables per size, threshold {THRESHOLD}. Hungarian: "
        "``assign`` (scipy.optimize.linear_sum_assignment over the acceptable pairs). Greedy: best remaining "
        f"pair first. Brute force: every permutation, vectorised, up to {BRUTE_FORCE_LIMIT} x {BRUTE_FORCE_LIMIT}. "
        "Times are the median per table; 'wrong' counts percepts not given their true anchor.",
        parameters={"sizes": list(sizes), "tables_per_size": tables_per_size},
    )
    rows = []
    curves: dict[str, list[float | None]] = {"Hungarian (scipy)": [], "greedy": [], "brute force": []}
    summary: dict[int, dict[str, float]] = {}
    for size in sizes:
        tables = [scored_table(size, rng) for _ in range(tables_per_size)]
        hungarian_ms = statistics.median(
            median_seconds(lambda t=table: assign(t, THRESHOLD), repeats) for table, _ in tables) * 1e3
        greedy_ms = statistics.median(median_seconds(lambda t=table: greedy(t), repeats) for table, _ in tables) * 1e3
        hungarian_wrong = greedy_wrong = suboptimal = agree = 0
        for table, truth in tables:
            optimal, fast = assign(table, THRESHOLD).matches, greedy(table)
            hungarian_wrong += wrong(optimal, truth)
            greedy_wrong += wrong(fast, truth)
            suboptimal += weight(table, fast) < weight(table, optimal) - 1e-9
        brute_ms = None
        if size <= BRUTE_FORCE_LIMIT:
            sample = tables[: max(3, tables_per_size // 5)]
            brute_ms = statistics.median(
                median_seconds(lambda t=table: brute_force_weight(t), 1, warm_up=0) for table, _ in sample) * 1e3
            agree = sum(abs(brute_force_weight(t) - weight(t, assign(t, THRESHOLD).matches)) < 1e-9
                        for t, _ in sample)
            summary.setdefault(size, {})["agree"] = 100.0 * agree / len(sample)
        percepts = size * tables_per_size
        summary.setdefault(size, {}).update(
            hungarian_ms=hungarian_ms, greedy_ms=greedy_ms, brute_ms=brute_ms or float("nan"),
            hungarian_wrong=100.0 * hungarian_wrong / percepts, greedy_wrong=100.0 * greedy_wrong / percepts)
        rows.append([size, round(hungarian_ms, 4), round(greedy_ms, 4),
                     round(brute_ms, 2) if brute_ms is not None else "-",
                     f"{100.0 * hungarian_wrong / percepts:.1f}", f"{100.0 * greedy_wrong / percepts:.1f}",
                     f"{100.0 * suboptimal / tables_per_size:.0f}"])
        curves["Hungarian (scipy)"].append(hungarian_ms)
        curves["greedy"].append(greedy_ms)
        curves["brute force"].append(brute_ms)
        print(f"  {size:>3} x {size:<3}: Hungarian {hungarian_ms:.3f} ms, greedy {greedy_ms:.3f} ms"
              + (f", brute force {brute_ms:.1f} ms" if brute_ms is not None else ""), flush=True)

    middle = 20
    brute_size = max(size for size in summary if "agree" in summary[size])
    result.figure(f"Hungarian, {middle} x {middle}", summary[middle]["hungarian_ms"], "ms/table",
                  baseline=summary[middle]["greedy_ms"], baseline_name="greedy")
    result.figure(f"Hungarian, {brute_size} x {brute_size}", summary[brute_size]["hungarian_ms"], "ms/table",
                  baseline=summary[brute_size]["brute_ms"], baseline_name="brute force")
    result.figure(f"percepts given the wrong anchor, {middle} x {middle}", summary[middle]["hungarian_wrong"], "%",
                  baseline=summary[middle]["greedy_wrong"], baseline_name="greedy")
    agreement = min(values["agree"] for values in summary.values() if "agree" in values)
    result.figure("Hungarian's total score equals brute force's", agreement, "% of tables", target="100 %",
                  met=agreement == 100.0)
    result.tables.append(Table(
        "per table size", ["n x n", "Hungarian ms", "greedy ms", "brute force ms", "Hungarian wrong %",
                           "greedy wrong %", "greedy below optimum, % of tables"], rows))
    result.line_plots.append(LinePlot("assignment", "assignment time per table", "n (percepts = anchors)",
                                      "ms per table", [float(s) for s in sizes], curves, log_x=True, log_y=True))
    return result


def main() -> int:
    return script.main(run, __doc__)


if __name__ == "__main__":
    raise SystemExit(main())
