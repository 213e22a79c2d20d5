#!/usr/bin/python3
"""Calibrates the aligner's decision on the calibration data only.

Usage: /usr/bin/python3 scripts/calibrate_decision.py [--all] CANDIDATES.csv [MORE.csv ...]

Prints the best fits (the best for each runner-up weight, and the top
TOP_FITS overall; --all: every combination tried), then the ini keys.

The CSVs come from the benchmark (bench/multires_bench writes candidates.csv:
every refined hypothesis of every pair, its features and whether it was right
against the truth). Only rows marked calibration=1 are used: Halmstad E5 and
HIH sensor pairs (positives, both orders in data made since a145d9e), cross-site pairs with an E5 map, the CARMEN
different-building and disjoint-part pairs at both resolution orders, the
first 15 % of a CARMEN run against a whole other building (little seen: the
evidence discount decides), and every E5 and HIH map against its own mirror
image (negatives), and the live bench's growing maps at a few states (site
"live": each fr079 robot against each other, whose wrong best candidates
must not merge, and against the intel robot, negatives). F5 and KPT4A rows
are the acceptance set and are never read here.

The decision (src/CScalingGridMapAligner.cpp) scores each refined candidate by
    score = B + chance_weight * (B - C) - sqrt(evidence / n)
            + feature_weight * min(F, feature_cap) / feature_cap
where T is the tolerant consistency (share of both maps' wall points moved
onto seen space that do not land on clearly free space), B the same with
each tile of 30 coarse cells of the moved walls shifted as its neighbours
fit best (the bent consistency: as if a smooth bend were taken out; the
shifts below), C the best T under far perturbations of the transform (what
chance gives in these maps), and n
the number of wall points judged (the weaker direction): neighbouring wall
points are far from independent, so a T measured on a small overlap (a map
shrunk into a corner of the other) is discounted like a proportion from few
samples, and F the number of SIFT matches between the maps (RANSAC's
input) that the transform takes onto each other: local appearance agreeing,
evidence beside the walls between look-alike buildings. The pair is then
decided on its best-scoring candidate by
    value = score + runner_up_weight * (score - max(floor, rival))
where rival is the best score of a candidate that puts the other map
elsewhere (its wall centroid more than distinct_shift coarse cells away,
turned by more than verify_turn_deg, or scaled by more than 10 %): the right
alignment of one building stands out, a chance fit between two buildings has
rivals nearly as good. The other map's mirror image is aligned too (the
aligner's mirror_check; rows with mirrored=1): each of its candidates is a
rival and never the best, so a map against its own mirror image, which fits
itself mirrored exactly, is refused. The pair is merged when value >=
threshold, and only if its best candidate's B leads C by the minimum lead
and its wall alignment A (of the wall points near a wall of the other map
that has a direction, the share near one running the same way, within
about 20 degrees) reaches the minimum wall alignment: independent maps of
one building differ in where their walls are by a few cells, not in which
way they run, while a wrong alignment lays walls across walls. Nor unless
its shift coherence H (tiles of 30 coarse cells of the moved walls, each
given the small shift, within 8 coarse cells, that fits it best: the share
of adjacent tiles whose shifts agree within the tolerance) reaches the
minimum: SLAM bends a map smoothly, a wrong alignment that lays walls near
walls fits each region by a shift of its own.

This script picks chance_weight, evidence, feature_weight and feature_cap,
runner_up_weight, floor, the
minimum lead, the minimum wall alignment, the minimum shift coherence and
distinct_shift (the most right merges; ties go to the fit that asks most of a candidate
with no rival, i.e. the highest lowest mergeable score
(threshold + runner_up_weight * floor) / (1 + runner_up_weight), to three
decimals: a best candidate alone, as on a small overlap or a map of a new
building, is what the calibration data checks least, and the screen drops
more below a higher bar; then to the smaller runner-up weight, the smaller
feature weight (the walls are what the data checks most), the smaller
distinct shift (more candidates are rivals), then the
larger chance weight, evidence, floor, minimum lead, wall alignment and
shift coherence: the safer where it costs nothing; a coherence gate must
stay COHERENCE_MARGIN below every right best candidate's) and sets
threshold just above the highest value any pair whose best candidate is
wrong reaches, plus a safety margin, so that no calibration pair would be
merged wrong, and treats a wrong pair just below a gate (ALIGNMENT_MARGIN,
LEAD_MARGIN, COHERENCE_MARGIN) as through it. It prints
the ini keys.

Each CSV given is a sample of its own: the same pair aligned by another
build or on another machine (other floating-point paths in OpenCV's SIFT
and warps) has other hypotheses, hence other rivals, and a wrong candidate's
value moves with its rival's score times the runner-up weight. The fit must
hold on every sample given; merges are counted over all of them. The
defaults need not be the top line: a fit may fail a negative the data lacks
(docs/decision.md).

The data comes from `multires_bench --calibration-data`: the aligner as it
runs (the screen on), with exhaustive_search so that every hypothesis is
refined and the structure always searched. Rows with screened=1 were dropped
by the screen (scored on a sample, below the lowest score that can merge
less screen_margin, which is about the floor): as in the aligner, they are
neither a pair's best nor anyone's rival. The screen's bar follows from the
decision (lowestMergeableScore): after changing the defaults, regenerate the
data and check that the fit stays.
"""
import collections
import csv
import io
import itertools
import math
import os
import subprocess
import sys
import tempfile

# Safety margin above the highest wrong value, in score units: the decision
# value moves (1 + runner-up weight) times as much as a score, so the margin
# does too (a quarter of the confidence scale, 0.2 (1 + weight) per unit).
# Why this large: docs/decision.md, "The current defaults".
MARGIN = 0.05
# The gates need margins too: a wrong pair's wall alignment or lead over
# chance moves by a few hundredths with the machine and build (other
# hypotheses, other refinements); one that sits just below a gate would merge
# where it crosses it. So a wrong pair within these margins below a gate sets
# the threshold as if it had passed.
ALIGNMENT_MARGIN = 0.02
LEAD_MARGIN = 0.01
COHERENCE_MARGIN = 0.02
WEIGHTS = [0.5, 1.0, 1.5]
EVIDENCE = [200, 400, 1000]
RUNNER_UP = [0.0, 1.0, 2.0, 3.0, 4.0, 6.0, 10.0]
# No floor above 0.25: right best candidates score about 0.3-0.6 (median
# 0.44), and a floor above a pair's score silences its rivals, however
# close (a floor of 0.5 fits two more calibration pairs by merging pairs
# whose best candidate has a rival at nearly its own score).
FLOORS = [-0.5, 0.0, 0.25]
# decision_min_lead: the best candidate's tolerant consistency must exceed
# chance by this to merge on its walls.
LEADS = [0.0, 0.02, 0.04]
# decision_min_wall_alignment (0: no gate).
ALIGNMENTS = [0.0, 0.7, 0.72, 0.74, 0.75, 0.76, 0.77, 0.78, 0.8]
# decision_min_shift_coherence (0: no gate).
COHERENCES = [0.0, 0.2, 0.25, 0.3]
# decision_feature_weight and decision_feature_cap: the score gains
# weight * min(m, cap) / cap for m agreeing feature matches (0: walls only).
FEATURES = [(0.0, 20)] + [(fw, cap) for fw in [0.1, 0.2, 0.4] for cap in [10, 20, 40]]
TOP_FITS = 20
# distinct_shift, coarse cells: how far apart two candidates' wall centroids
# must lie to be rivals, not one answer. Independent maps bend by several
# cells, so one building's right placement is refined to several optima, a
# bend apart (20-35 cells on Halmstad E5), which rival each other at a small
# shift. No more than 40: at 5 cm, 2 m, the displacement the benchmark still
# calls right; a candidate farther away places the map elsewhere by that
# measure (E5_13 <- E5_04's stretched near miss lies 54 cells from the right
# placement) and must stay a rival.
DISTINCT_SHIFTS = [20.0, 30.0, 40.0]
TURN_DEG = 8.0  # the aligner's verify_turn_deg
MIN_JUDGED = 40  # the aligner's kMinJudgedPoints
# A live-fleet pair's best candidate off by more than 2 coarse cells (not
# right) but at most this many is the right placement slid along a corridor
# of a barely grown map (the finish refines it on every cell): neither right
# nor wrong here. Farther ones are wrong. (Halmstad's own rule is the
# annotation's: right within its tolerance, else wrong.)
LIVE_NEAR_CELLS = 5.0


def load(paths):
    rows = []
    for path in paths:
        with open(path) as f:
            for r in csv.DictReader(f):
                if r.get("centre_x") is None or r["calibration"] != "1":
                    continue
                rows.append({
                    # Each file is its own sample of the pairs: the same pair
                    # aligned by another build or machine has other hypotheses.
                    "pair": (r["site"], r["ref"], r["other"], path),
                    "positive": r["positive"] == "1",
                    "right": r["right"] == "1",
                    "near": (r["site"] == "live" and r["right"] != "1" and r["error"] != "nan"
                             and float(r["error"]) <= LIVE_NEAR_CELLS),
                    "screened": r.get("screened") == "1",
                    "mirrored": r.get("mirrored") == "1",
                    # Absent from data written before it was measured: T there.
                    "B": float(r.get("bent_consistency") or r["tolerant_consistency"]),
                    "C": float(r["chance_consistency"]),
                    # Absent from data written before it was measured: no gate there.
                    "A": float(r.get("wall_alignment") or "nan"),
                    "H": float(r.get("shift_coherence") or "nan"),
                    # Absent from data written before it was measured: none.
                    "F": int(r.get("feature_agreement") or 0),
                    "n": max(1.0, float(r["judged"])),
                    "scale": float(r["scale"]),
                    "yaw": math.radians(float(r["yaw_deg"])),
                    "centre": (float(r["centre_x"]), float(r["centre_y"])),
                })
    return rows


def distinct(a, b, shift_cells):
    coarse = max(1.0, a["scale"], b["scale"])
    turn = abs(math.remainder(a["yaw"] - b["yaw"], 2 * math.pi))
    shift = math.hypot(a["centre"][0] - b["centre"][0], a["centre"][1] - b["centre"][1])
    return (shift > shift_cells * coarse or turn > math.radians(TURN_DEG)
            or abs(math.log(a["scale"] / b["scale"])) > math.log(1.1))


def main():
    show_all = "--all" in sys.argv[1:]
    paths = [a for a in sys.argv[1:] if a != "--all"]
    if not paths:
        sys.exit(__doc__)
    rows = load(paths)
    pairs = collections.defaultdict(list)
    for r in rows:
        pairs[r["pair"]].append(r)
    # Which candidates are rivals of which does not depend on the weights.
    rivals_at = {ds: {id(r): [o for o in c if o is not r and not o["screened"] and (o["mirrored"] or distinct(r, o, ds))]
                      for c in pairs.values() for r in c}
                 for ds in DISTINCT_SHIFTS}
    # Merges are counted on the Halmstad positives only (the tuning set);
    # the live fleet's same-building pairs (site "live") only weigh where their
    # best candidate is wrong: a barely grown map the fleet must not place.
    positives = [k for k, c in pairs.items() if c[0]["positive"] and k[0] != "live"]
    reachable = [k for k in positives if any(x["right"] for x in pairs[k])]
    live = [k for k, c in pairs.items() if c[0]["positive"] and k[0] == "live"]
    print(f"calibration data: {len(rows)} candidates, {len(positives)} positive pairs "
          f"({len(reachable)} with a right candidate), {len(live)} live-fleet same-building pairs, "
          f"{len(pairs) - len(positives) - len(live)} negative pairs")
    best = None
    fits = []  # (rank, runner-up weight, line) of every combination tried
    for w, e, (fw, fcap) in itertools.product(WEIGHTS, EVIDENCE, FEATURES):
        def score(r):
            return r["B"] + w * (r["B"] - r["C"]) - math.sqrt(e / r["n"]) + fw * min(r["F"], fcap) / fcap
        scores = {id(r): score(r) for r in rows}
        tops = {}
        for key, c in pairs.items():
            judged = [r for r in c if not r["screened"] and not r["mirrored"] and r["n"] >= MIN_JUDGED]
            if judged:
                tops[key] = max(judged, key=lambda r: scores[id(r)])
        # A coherence gate is for the wrong tops: one that some right best
        # candidate does not clear by the margin would trim merges of new
        # maps for no gain here.
        right_tops = [tops[key]["H"] for key in positives if key in tops and tops[key]["right"]]
        cohs = [h for h in COHERENCES if not right_tops or h <= min(right_tops) - COHERENCE_MARGIN]
        for k, floor, lead, align, coh, ds in itertools.product(
                RUNNER_UP, FLOORS, LEADS, ALIGNMENTS, cohs, DISTINCT_SHIFTS):
            rivals = rivals_at[ds]

            def value(top):
                s = scores[id(top)]
                rival = max([floor] + [scores[id(o)] for o in rivals[id(top)]])
                return s + k * (s - rival)
            # A top not leading chance by `lead`, whose near walls run
            # alike less than `align`, or whose regions shift alike less
            # than `coh`, cannot merge: below any threshold. Wrong tops
            # within the gates' margins count as through them.
            def through(top, lead_margin, align_margin, coh_margin):
                return (top["B"] - top["C"] >= lead - lead_margin and not top["A"] < align - align_margin
                        and not top["H"] < coh - coh_margin)
            values = {key: value(top) if through(top, 0, 0, 0) else -math.inf for key, top in tops.items()}
            wrong = [value(top) if through(top, LEAD_MARGIN, ALIGNMENT_MARGIN, COHERENCE_MARGIN) else -math.inf
                     for key, top in tops.items() if not top["right"] and not top["near"]]
            threshold = max(wrong) + MARGIN * (1 + k)
            merged_right = sum(1 for key in positives
                               if key in tops and tops[key]["right"] and values[key] >= threshold)
            live_right = sum(1 for key in live
                             if key in tops and tops[key]["right"] and values[key] >= threshold)
            lowest_mergeable = round((threshold + k * floor) / (1 + k), 3)
            rank = (merged_right, lowest_mergeable, -k, -fw, -ds, w, e, floor, lead, align, coh, fcap)
            fits.append((rank, k,
                         f"  chance_weight {w:4.2f} evidence {e:4d} features {fw:3.1f}/{fcap:2d} "
                         f"runner_up_weight {k:3.1f} floor {floor:5.2f} "
                         f"lead {lead:4.2f} alignment {align:4.2f} coherence {coh:4.2f} distinct {ds:2.0f}: "
                         f"highest wrong {max(wrong):.3f}, threshold {threshold:.3f}, "
                         f"merged right {merged_right}/{len(positives)}, live {live_right}/{len(live)}"))
            if best is None or rank > best[0]:
                # Per file, and in the report's order (REF the later map).
                per_file = collections.Counter(
                    (key[3], key[1] > key[2]) for key in positives
                    if key in tops and tops[key]["right"] and values[key] >= threshold)
                best = (rank, w, e, fw, fcap, k, floor, lead, align, coh, ds, threshold, merged_right, live_right,
                        per_file)
    if show_all:
        print("every fit tried:")
        for _, _, line in fits:
            print(line)
    else:
        print("the best fit for each runner-up weight:")
        for weight in RUNNER_UP:
            print(max((f for f in fits if f[1] == weight), key=lambda f: f[0])[2])
        print(f"the {TOP_FITS} best fits (of {len(fits)}; --all prints every one):")
        for _, _, line in sorted(fits, key=lambda f: f[0], reverse=True)[:TOP_FITS]:
            print(line)
    _, w, e, fw, fcap, k, floor, lead, align, coh, ds, threshold, merged_right, live_right, per_file = best
    ini = (f"[aligner]\ndecision_chance_weight = {w}\ndecision_evidence = {e}\n"
           f"decision_feature_weight = {fw}\ndecision_feature_cap = {fcap}\ndecision_min_lead = {lead}\n"
           f"decision_min_wall_alignment = {align}\ndecision_min_shift_coherence = {coh}\n"
           f"decision_runner_up_weight = {k}\ndecision_runner_up_floor = {floor}\ndistinct_shift = {ds}\n"
           f"decision_threshold = {threshold:.3f}\n")
    print("\n" + ini, end="")
    # The fit as the aligner decides it (its own code, not this script's).
    replayed = replay(paths, ini)
    if replayed is None:
        print("# decision-replay not built: the fit was not replayed by the aligner's decision")
    else:
        print(f"# replayed by the aligner's decision (decision-replay): {replayed[0]} positive pairs merged right, "
              f"{replayed[1]} merged wrong")
        if replayed != (merged_right, 0):
            sys.exit(f"calibrate_decision.py: the aligner's decision disagrees with this script's: {replayed} "
                     f"against ({merged_right}, 0)")
    print(f"# calibration: {merged_right}/{len(positives)} positive pairs merged right, 0 wrong "
          f"(margin {MARGIN} x (1 + runner-up weight) above the highest wrong value); live fleet pairs merged right "
          f"{live_right}/{len(live)}")
    for path in paths:
        n = sum(1 for key in positives if key[3] == path)
        n_later = sum(1 for key in positives if key[3] == path and key[1] > key[2])
        print(f"#   {path}: {per_file[(path, True)] + per_file[(path, False)]}/{n} positive pairs merged right, "
              f"{per_file[(path, True)]}/{n_later} with the later map as REF (the report's order)")


def replay(paths, ini_text):
    """The fit replayed by the aligner's own decision (decision-replay): the
    calibration positives merged right and the pairs merged wrong, over all
    samples, by the same rules as above. None when the tool is not built."""
    tool = os.environ.get("DECISION_REPLAY") or os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "build", "devel", "lib", "multires_map_merge",
        "decision-replay")
    if not os.path.exists(tool):
        return None
    with tempfile.NamedTemporaryFile("w", suffix=".ini") as ini:
        ini.write(ini_text)
        ini.flush()
        right = wrong = 0
        for path in paths:
            out = subprocess.run([tool, path, "--config", ini.name], check=True, capture_output=True, text=True).stdout
            for r in csv.DictReader(io.StringIO(out)):
                if r["calibration"] != "1" or r["merged"] != "1":
                    continue
                near = (r["site"] == "live" and r["right"] != "1" and r["error"] != "nan"
                        and float(r["error"]) <= LIVE_NEAR_CELLS)
                if r["right"] == "1":
                    right += r["site"] != "live"
                elif not near:
                    wrong += 1
    return right, wrong


if __name__ == "__main__":
    main()
