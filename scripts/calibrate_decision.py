#!/usr/bin/python3
"""Calibrates the aligner's decision on the calibration data only, and
validates the fit leave-one-site-out.

Usage: /usr/bin/python3 scripts/calibrate_decision.py [--all] [--markdown FILE] [--expect-defaults INI]
           CANDIDATES.csv [MORE.csv ...]

Prints the best fits (the best for each runner-up weight, and the top
TOP_FITS overall; --all: every combination tried), the leave-one-site-out
table, then the ini keys. --markdown FILE also writes the leave-one-site-out
table as Markdown (the benchmark report's section). --expect-defaults INI
(as `gridmap-merge --write-config INI` writes the aligner's defaults) exits 1
unless the fit is those defaults (ctest calibration_fit_is_the_defaults).

The CSVs come from the benchmark (`multires_bench --calibration-data` writes
candidates.csv: every refined hypothesis of every pair, its evidence and
whether it was right against the truth). Only rows marked calibration=1 are
used: Halmstad E5 and HIH sensor pairs in both orders and each E5 and HIH
sensor map on its own site's floor plan (positives); cross-site pairs with an
E5 or HIH map, each E5 and HIH sensor map on the other sites' floor plans, the
CARMEN different-building and disjoint-part pairs, the first 15 % of a CARMEN
run against a whole other building, every E5 and HIH map against its own
mirror image, and the live bench's growing maps at a few states (site "live":
each fr079 robot against each other, whose wrong best candidates must not
merge, and against the intel robot), and the independent ROS maps (site
"ros": every ordered pair of a place, positives judged against a
brute-force truth, and every map against the other places' maps). The E5/HIH pairs with OTHER recorded
coarser are left out (not_fitted). F5 and KPT4A are the acceptance set:
their own pairs are never read here; their maps and plans serve only as
other buildings for E5 and HIH maps.

The model (src/Decision.cpp, docs/decision.md) scores each candidate by
    score = B + chance_weight * (B - C) - sqrt(evidence / n)
            + feature_weight * min(F, feature_cap) / feature_cap
(B bent consistency, C chance consistency, n judged wall points, F agreeing
feature matches) and decides a pair on its best-scoring candidate by
    value = score + runner_up_weight * (score - max(floor, rival))
with rival the best score of a candidate placing the other map elsewhere
(more than distinct_shift coarse cells, verify_turn_deg or 10 % of scale
away; every candidate of the mirrored map). It merges when value >= threshold.
Fitted numbers: chance_weight, evidence, feature_weight, feature_cap,
runner_up_weight, floor, distinct_shift and the threshold.

The fit: for each combination of the first seven on the grids below, the
threshold is set the safety margin above the highest value any pair whose
best candidate is wrong reaches; the fit merging the most positive pairs
right wins (ties: the highest lowest mergeable score, i.e. the most asked of
a best candidate with no rival, which the data checks least; then the
smaller runner-up weight, feature weight and distinct shift; then the larger
chance weight, evidence and floor).

Leave-one-site-out: the calibration pairs are grouped by the calibration
sites they touch (E5, HIH, CARMEN, the live fleet, the ROS maps); for each group the fit is
made on the pairs that do not touch it and judged on those that do: how many
of its positives merge right, how many pairs merge wrong, and by how much its
highest wrong value overshoots the highest wrong value the fit saw. The
margin is then the larger of MARGIN and the largest overshoot: what a new
site added above what the others had shown.

Each CSV given is a sample of its own: the same pair aligned by another
build or on another machine has other hypotheses, hence other rivals. The
fit must hold on every sample given; merges are counted over all of them.
Rows with screened=1 were dropped by the aligner's screen: as in the aligner,
they are neither a pair's best nor anyone's rival. The screen's bar follows
from the decision (lowestMergeableScore): after changing the defaults,
regenerate the data and check that the fit stays.
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

# Safety margin above the highest wrong value, in score units (the decision
# value moves (1 + runner-up weight) times as much as a score, so the margin
# does too: a quarter of the confidence scale). The least margin: the
# leave-one-site-out overshoot raises it (docs/decision.md).
MARGIN = 0.05
WEIGHTS = [0.5, 1.0, 1.5]
EVIDENCE = [200, 400, 1000]
RUNNER_UP = [0.0, 1.0, 2.0, 3.0, 4.0, 6.0, 10.0]
# No floor above 0.25: right best candidates score about 0.3-0.6, and a
# floor above a pair's score silences its rivals, however close.
FLOORS = [-0.5, 0.0, 0.25]
# (feature_weight, feature_cap): the score gains weight * min(F, cap) / cap.
FEATURES = [(0.0, 20)] + [(fw, cap) for fw in [0.1, 0.2, 0.4] for cap in [10, 20, 40]]
# No more than 40 coarse cells: at 5 cm, 2 m, the displacement the benchmark
# still calls right; a candidate farther away places the map elsewhere and
# must stay a rival.
DISTINCT_SHIFTS = [20.0, 30.0, 40.0]
TOP_FITS = 20
TURN_DEG = 8.0  # DecisionParams::distinct_turn_deg
MIN_JUDGED = 40  # DecisionParams::min_judged_points
# A live-fleet pair's best candidate off by more than 2 coarse cells (not
# right) but at most this many is the right placement slid along a corridor
# of a barely grown map (the finish refines it on every cell): neither right
# nor wrong here. Farther ones are wrong.
LIVE_NEAR_CELLS = 5.0
CALIBRATION_SITES = ("E5", "HIH")
# Leave-one-site-out groups, in the table's order.
GROUPS = ("E5", "HIH", "carmen", "live", "ros")

Fit = collections.namedtuple("Fit", "rank w e fw fcap k floor ds threshold highest_wrong merged_right live_right")


def load(paths):
    rows = []
    for path in paths:
        with open(path) as f:
            for r in csv.DictReader(f):
                if r.get("centre_x") is None or r["calibration"] != "1" or not_fitted(r):
                    continue
                rows.append({
                    # Each file is its own sample of the pairs.
                    "pair": (r["site"], r["ref"], r["other"], path),
                    "positive": r["positive"] == "1",
                    "right": r["right"] == "1",
                    "near": (r["site"] == "live" and r["right"] != "1" and r["error"] != "nan"
                             and float(r["error"]) <= LIVE_NEAR_CELLS),
                    "screened": r.get("screened") == "1",
                    "mirrored": r.get("mirrored") == "1",
                    "B": float(r["bent_consistency"]),
                    "C": float(r["chance_consistency"]),
                    "F": int(r["feature_agreement"]),
                    "n": max(1.0, float(r["judged"])),
                    "scale": float(r["scale"]),
                    "yaw": math.radians(float(r["yaw_deg"])),
                    "centre": (float(r["centre_x"]), float(r["centre_y"])),
                })
    return rows


def not_fitted(row):
    """Pairs the calibration data holds but the fit leaves out (docs/decision.md,
    Calibration): OTHER recorded coarser (`other` E5_05_x2). Their highest
    wrong best candidate (E5_11 <- E5_05 x2, 0.702) has the evidence of the
    weakest right merges; fitting it moves the grid to a threshold that
    refuses a seventh of E5's sensor pairs and most of its floor plans.
    The benchmark reports them."""
    return "_x" in row["other"]


def groups_of(key):
    """The leave-one-site-out groups a pair touches."""
    site, ref, other, _ = key
    if site in ("carmen", "live", "ros"):
        return {site}
    return {name.split("_")[0] for name in (ref, other)} & set(CALIBRATION_SITES)


def distinct(a, b, shift_cells):
    coarse = max(1.0, a["scale"], b["scale"])
    turn = abs(math.remainder(a["yaw"] - b["yaw"], 2 * math.pi))
    shift = math.hypot(a["centre"][0] - b["centre"][0], a["centre"][1] - b["centre"][1])
    return (shift > shift_cells * coarse or turn > math.radians(TURN_DEG)
            or abs(math.log(a["scale"] / b["scale"])) > math.log(1.1))


class Data:
    """Candidates grouped by pair, with what the fit needs precomputed."""

    def __init__(self, pairs):
        self.pairs = pairs
        # Which candidates are rivals of which does not depend on the weights.
        self.rivals_at = {ds: {id(r): [o for o in c if o is not r and not o["screened"]
                                       and (o["mirrored"] or distinct(r, o, ds))]
                               for c in pairs.values() for r in c}
                          for ds in DISTINCT_SHIFTS}
        # Merges are counted on the Halmstad positives; the live fleet's
        # same-building pairs only weigh where their best candidate is wrong.
        self.positives = [k for k, c in pairs.items() if c[0]["positive"] and k[0] != "live"]
        self.live = [k for k, c in pairs.items() if c[0]["positive"] and k[0] == "live"]

    def subset(self, keep):
        return Data({k: c for k, c in self.pairs.items() if keep(k)})


def score_fn(w, e, fw, fcap):
    return lambda r: r["B"] + w * (r["B"] - r["C"]) - math.sqrt(e / r["n"]) + fw * min(r["F"], fcap) / fcap


def tops_of(data, score):
    """Each pair's best-scoring candidate judged in full, and every score."""
    scores = {id(r): score(r) for c in data.pairs.values() for r in c}
    tops = {}
    for key, c in data.pairs.items():
        judged = [r for r in c if not r["screened"] and not r["mirrored"] and r["n"] >= MIN_JUDGED]
        if judged:
            tops[key] = max(judged, key=lambda r: scores[id(r)])
    return tops, scores


def values_of(data, tops, scores, k, floor, ds):
    rivals = data.rivals_at[ds]
    values = {}
    for key, top in tops.items():
        s = scores[id(top)]
        values[key] = s + k * (s - max([floor] + [scores[id(o)] for o in rivals[id(top)]]))
    return values


def is_wrong(top):
    return not top["right"] and not top["near"]


def fit(data, margin):
    """Every combination of the grids, ranked; the threshold `margin` (score
    units) above the highest wrong value."""
    fits = []
    for w, e, (fw, fcap) in itertools.product(WEIGHTS, EVIDENCE, FEATURES):
        tops, scores = tops_of(data, score_fn(w, e, fw, fcap))
        for k, floor, ds in itertools.product(RUNNER_UP, FLOORS, DISTINCT_SHIFTS):
            values = values_of(data, tops, scores, k, floor, ds)
            highest_wrong = max([-math.inf] + [values[key] for key, top in tops.items() if is_wrong(top)])
            threshold = highest_wrong + margin * (1 + k)
            merged_right = sum(1 for key in data.positives
                               if key in tops and tops[key]["right"] and values[key] >= threshold)
            live_right = sum(1 for key in data.live if key in tops and tops[key]["right"] and values[key] >= threshold)
            lowest_mergeable = round((threshold + k * floor) / (1 + k), 3)
            rank = (merged_right, lowest_mergeable, -k, -fw, -ds, w, e, floor, fcap)
            fits.append(Fit(rank, w, e, fw, fcap, k, floor, ds, threshold, highest_wrong, merged_right, live_right))
    fits.sort(key=lambda f: f.rank, reverse=True)
    return fits


def judge(data, f):
    """The fit `f` on `data`: positives merged right, pairs merged wrong, the
    highest wrong value."""
    tops, scores = tops_of(data, score_fn(f.w, f.e, f.fw, f.fcap))
    values = values_of(data, tops, scores, f.k, f.floor, f.ds)
    merged_right = sum(1 for key in data.positives if key in tops and tops[key]["right"] and values[key] >= f.threshold)
    wrong = [values[key] for key, top in tops.items() if is_wrong(top)]
    merged_wrong = sum(1 for v in wrong if v >= f.threshold)
    return merged_right, merged_wrong, max([-math.inf] + wrong)


def describe(f):
    return (f"chance_weight {f.w:4.2f} evidence {f.e:4d} features {f.fw:3.1f}/{f.fcap:2d} "
            f"runner_up_weight {f.k:4.1f} floor {f.floor:5.2f} distinct {f.ds:2.0f}: "
            f"highest wrong {f.highest_wrong:.3f}, threshold {f.threshold:.3f}, "
            f"merged right {f.merged_right}, live {f.live_right}")


def leave_one_site_out(data, chosen):
    """Per group, fitted on the pairs that do not touch it and judged on
    those that do, two ways: the whole fit made again (how well the fitting
    generalizes), and the `chosen` fit's model with only its threshold set
    again (how far a new site's wrong values rise above the others': the
    margin's validation). Returns table rows and the largest overshoot of the
    second, in score units."""
    rows, overshoot = [], 0.0
    for group in GROUPS:
        train = data.subset(lambda k: group not in groups_of(k))
        test = data.subset(lambda k: group in groups_of(k))
        refit = fit(train, MARGIN)[0]
        refit_right, refit_wrong, _ = judge(test, refit)
        _, _, train_highest = judge(train, chosen)
        fixed = chosen._replace(threshold=train_highest + MARGIN * (1 + chosen.k))
        fixed_right, fixed_wrong, highest = judge(test, fixed)
        over = (highest - train_highest) / (1 + chosen.k)
        overshoot = max(overshoot, over)
        rows.append((group, len(train.pairs), len(test.positives), len(test.pairs) - len(test.positives) - len(test.live),
                     refit, refit_right, refit_wrong, fixed, fixed_right, fixed_wrong, train_highest, highest, over))
    return rows, overshoot


def loso_markdown(rows, overshoot, margin):
    lines = ["| left out | pairs fitted on | its positive pairs | its negative pairs "
             "| refit: model (chance w., evidence, features, runner-up w., floor, distinct) | merged right | merged wrong "
             "| this model: threshold | merged right | merged wrong | highest wrong value, fitted / left out "
             "| overshoot [score units] |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for (group, n_train, n_pos, n_neg, refit, refit_right, refit_wrong, fixed, fixed_right, fixed_wrong,
         train_highest, highest, over) in rows:
        lines.append(f"| {group} | {n_train} | {n_pos} | {n_neg} "
                     f"| {refit.w}, {refit.e}, {refit.fw}/{refit.fcap}, {refit.k}, {refit.floor}, {refit.ds:.0f} "
                     f"| {refit_right} / {n_pos} | {refit_wrong} | {fixed.threshold:.3f} | {fixed_right} / {n_pos} "
                     f"| {fixed_wrong} | {train_highest:.3f} / {highest:.3f} | {over:+.3f} |")
    lines.append("")
    lines.append(f"Largest overshoot of this model: {overshoot:+.3f}; the margin above the highest wrong value is "
                 f"max({MARGIN}, overshoot) = **{margin:.3f}** score units.")
    return "\n".join(lines) + "\n"


def main():
    args = sys.argv[1:]
    show_all = "--all" in args
    def option(name):
        if name not in args:
            return None
        i = args.index(name)
        value = args[i + 1]
        del args[i:i + 2]
        return value
    markdown = option("--markdown")
    expected_ini = option("--expect-defaults")
    paths = [a for a in args if a != "--all"]
    if not paths:
        sys.exit(__doc__)
    rows = load(paths)
    pairs = collections.defaultdict(list)
    for r in rows:
        pairs[r["pair"]].append(r)
    data = Data(dict(pairs))
    reachable = [k for k in data.positives if any(x["right"] for x in data.pairs[k])]
    print(f"calibration data: {len(rows)} candidates, {len(data.positives)} positive pairs "
          f"({len(reachable)} with a right candidate), {len(data.live)} live-fleet same-building pairs, "
          f"{len(data.pairs) - len(data.positives) - len(data.live)} negative pairs")

    # The model fitted with the least margin, its margin validated leave
    # one site out, and the fit made again with that margin.
    chosen = fit(data, MARGIN)[0]
    loso, overshoot = leave_one_site_out(data, chosen)
    margin = max(MARGIN, overshoot)
    table = loso_markdown(loso, overshoot, margin)
    print("leave-one-site-out (each group fitted without it, judged on it):")
    print(table)
    if markdown:
        with open(markdown, "w") as out:
            out.write(table)

    fits = fit(data, margin)
    if show_all:
        print("every fit tried:")
        for f in fits:
            print("  " + describe(f))
    else:
        print("the best fit for each runner-up weight:")
        for weight in RUNNER_UP:
            print("  " + describe(next(f for f in fits if f.k == weight)))
        print(f"the {TOP_FITS} best fits (of {len(fits)}; --all prints every one):")
        for f in fits[:TOP_FITS]:
            print("  " + describe(f))
    best = fits[0]
    ini = (f"[aligner]\ndecision_chance_weight = {best.w}\ndecision_evidence = {best.e}\n"
           f"decision_feature_weight = {best.fw}\ndecision_feature_cap = {best.fcap}\n"
           f"decision_runner_up_weight = {best.k}\ndecision_runner_up_floor = {best.floor}\n"
           f"distinct_shift = {best.ds}\ndecision_threshold = {best.threshold:.3f}\n")
    print("\n" + ini, end="")
    tops, scores = tops_of(data, score_fn(best.w, best.e, best.fw, best.fcap))
    values = values_of(data, tops, scores, best.k, best.floor, best.ds)
    # The fit as the aligner decides it (its own code, not this script's).
    replayed = replay(paths, ini)
    if replayed is None:
        print("# decision-replay not built: the fit was not replayed by the aligner's decision")
    else:
        right, wrong, by_cells = replayed
        on_walls = {key for key in data.positives if tops.get(key, {}).get("right") and values[key] >= best.threshold}
        print(f"# replayed by the aligner's decision (decision-replay): {len(right)} positive pairs merged right "
              f"({len(by_cells & right)} on coinciding cells, which no fitted number moves), {len(wrong)} merged wrong")
        if right != on_walls | (by_cells & right) or wrong:
            sys.exit(f"calibrate_decision.py: the aligner's decision disagrees with this script's: "
                     f"{len(right)} merged right, {len(wrong)} wrong, against {len(on_walls)} on the walls and "
                     f"{len(by_cells & right)} on coinciding cells")
    if expected_ini:
        differ = differences(ini, expected_ini)
        if differ:
            sys.exit("calibrate_decision.py: the fit is not the aligner's defaults: " + "; ".join(differ))
        print(f"# the fit is the aligner's defaults ({expected_ini})")
    print(f"# calibration: {best.merged_right}/{len(data.positives)} positive pairs merged right, 0 wrong "
          f"(margin {margin:.3f} x (1 + runner-up weight) above the highest wrong value); live fleet pairs merged "
          f"right {best.live_right}/{len(data.live)}")
    for path in paths:
        keys = [key for key in data.positives if key[3] == path]
        merged = [key for key in keys if tops.get(key, {}).get("right") and values[key] >= best.threshold]
        # The report's order: sensor pairs with the later map as REF.
        def reported(key):
            return key[1] > key[2] and not key[1].endswith("_layout")
        print(f"#   {path}: {len(merged)}/{len(keys)} positive pairs merged right, "
              f"{sum(1 for key in merged if reported(key))}/{sum(1 for key in keys if reported(key))} sensor pairs "
              f"with the later map as REF (the report's order)")


def differences(fit_ini, defaults_path):
    """Keys of the fit whose value the defaults' ini (MRPT format: `key = value
    // comment`) does not hold, to the fit's printed precision."""
    def values(text):
        out = {}
        for line in text.splitlines():
            if "=" in line and not line.lstrip().startswith(("[", "#", "//")):
                key, value = line.split("=", 1)
                out[key.strip()] = value.split("//")[0].strip()
        return out
    with open(defaults_path) as f:
        defaults = values(f.read())
    differ = []
    for key, value in values(fit_ini).items():
        if key not in defaults or abs(float(defaults[key]) - float(value)) > 5e-4:
            differ.append(f"{key} fitted {value}, default {defaults.get(key, 'absent')}")
    return differ


def replay(paths, ini_text):
    """The fit replayed by the aligner's own decision (decision-replay): the
    calibration positive pairs merged right, the pairs merged wrong, and the
    pairs merged on coinciding cells (the exact path, whatever the walls'
    value: this script does not fit it), as sets of pair keys over all
    samples, by the same rules as above. None when the tool is not built."""
    tool = os.environ.get("DECISION_REPLAY") or os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "build", "devel", "lib", "multires_map_merge",
        "decision-replay")
    if not os.path.exists(tool):
        return None
    with tempfile.NamedTemporaryFile("w", suffix=".ini") as ini:
        ini.write(ini_text)
        ini.flush()
        right, wrong, by_cells = set(), set(), set()
        for path in paths:
            out = subprocess.run([tool, path, "--config", ini.name], check=True, capture_output=True, text=True).stdout
            for r in csv.DictReader(io.StringIO(out)):
                if r["calibration"] != "1" or r["merged"] != "1" or not_fitted(r):
                    continue
                key = (r["site"], r["ref"], r["other"], path)
                near = (r["site"] == "live" and r["right"] != "1" and r["error"] != "nan"
                        and float(r["error"]) <= LIVE_NEAR_CELLS)
                if r["by_cells"] == "1":
                    by_cells.add(key)
                if r["right"] == "1":
                    if r["site"] != "live":
                        right.add(key)
                elif not near:
                    wrong.add(key)
    return right, wrong, by_cells


if __name__ == "__main__":
    main()
