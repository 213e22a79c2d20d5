#!/usr/bin/python3
"""Calibrates the aligner's decision on the calibration data only.

Usage: /usr/bin/python3 scripts/calibrate_decision.py CANDIDATES.csv [MORE.csv ...]

The CSVs come from the benchmark (bench/multires_bench writes candidates.csv:
every refined hypothesis of every pair, its features and whether it was right
against the truth). Only rows marked calibration=1 are used: Halmstad E5 and
HIH sensor pairs (positives), cross-site pairs with an E5 map, the CARMEN
different-building and disjoint-part pairs at both resolution orders, and
every E5 and HIH map against its own mirror image (negatives). F5 and KPT4A rows are
the acceptance set and are never read here.

The decision (src/CScalingGridMapAligner.cpp) scores a refined candidate by
    score = T + chance_weight * (T - C) - sqrt(evidence / n)
where T is the tolerant consistency (share of both maps' wall points moved
onto seen space that do not land on clearly free space), C the best T under
far perturbations of the transform (what chance gives in these maps), and n
the number of wall points judged (the weaker direction): neighbouring wall
points are far from independent, so a T measured on a small overlap (a map
shrunk into a corner of the other) is discounted like a proportion from few
samples. The candidate is merged when score >= threshold. This script picks
chance_weight and evidence (the most right merges; ties go to the larger
chance weight, then the larger evidence) and sets threshold just above the
highest score any wrong candidate reaches, plus a safety margin, so that no
calibration candidate that is wrong would be merged. It prints the ini keys.

Rows with screened=1 were dropped by the aligner's cheap verification
(screen_points): judged on samples under the current decision, at least
screen_margin below its threshold. They are skipped; to weigh other chance
weights and evidence fairly, calibrate from a run with screen_points = 0.
"""
import csv
import collections
import math
import sys

MARGIN = 0.02  # safety margin above the highest wrong score
WEIGHTS = [0.0, 0.25, 0.5, 1.0, 1.5, 2.0]
EVIDENCE = [0, 10, 25, 50, 100, 200, 400]


def load(paths):
    rows = []
    for path in paths:
        with open(path) as f:
            for r in csv.DictReader(f):
                if r.get("initial_error") is None or r["calibration"] != "1":
                    continue
                if r.get("screened") == "1":
                    continue
                rows.append({
                    "pair": (r["site"], r["ref"], r["other"]),
                    "positive": r["positive"] == "1",
                    "right": r["right"] == "1",
                    "T": float(r["tolerant_consistency"]),
                    "C": float(r["chance_consistency"]),
                    "n": max(1, int(r["judged"])),
                })
    return rows


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    rows = load(sys.argv[1:])
    pairs = collections.defaultdict(list)
    for r in rows:
        pairs[r["pair"]].append(r)
    positives = [k for k, c in pairs.items() if c[0]["positive"]]
    reachable = [k for k in positives if any(x["right"] for x in pairs[k])]
    print(f"calibration data: {len(rows)} candidates, {len(positives)} positive pairs "
          f"({len(reachable)} with a right candidate), {len(pairs) - len(positives)} negative pairs")
    best = None
    for w in WEIGHTS:
        for k in EVIDENCE:
            def score(r):
                return r["T"] + w * (r["T"] - r["C"]) - math.sqrt(k / r["n"])
            highest_wrong = max(score(r) for r in rows if not r["right"])
            threshold = highest_wrong + MARGIN
            chosen = {key: max(pairs[key], key=score) for key in positives}
            merged_right = sum(1 for c in chosen.values() if c["right"] and score(c) >= threshold)
            print(f"  chance_weight {w:4.2f} evidence {k:3d}: highest wrong score {highest_wrong:.3f}, "
                  f"threshold {threshold:.3f}, merged right {merged_right}/{len(positives)}")
            if best is None or (merged_right, w, k) > best[:3]:
                best = (merged_right, w, k, threshold)
    merged_right, w, k, threshold = best
    print(f"\n[aligner]\ndecision_chance_weight = {w}\ndecision_evidence = {k}\n"
          f"decision_threshold = {threshold:.3f}")
    print(f"# calibration: {merged_right}/{len(positives)} positive pairs merged right, 0 wrong "
          f"(margin {MARGIN} above the highest wrong candidate)")


if __name__ == "__main__":
    main()
