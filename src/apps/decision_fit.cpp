// decision-fit: calibrates the aligner's decision (Decision.h) on the
// benchmark's calibration data and validates the fit leave one site out,
// by calling the aligner's own decide() for every pair and every point of
// the grid: one implementation of the decision (docs/decision.md,
// Calibration).
//
// Usage: decision-fit [--all] [--markdown FILE] [--expect-defaults] CANDIDATES.csv [MORE.csv ...]
//
// Prints the leave-one-site-out table, the best fits (the best for each
// runner-up weight and the TOP_FITS best; --all: every one), the ini keys of
// the fit, and what the fitted decision merges on each sample. --markdown
// FILE also writes the table as Markdown (the benchmark report's section).
// --expect-defaults exits 1 unless the fit is the aligner's defaults
// (ctest calibration_fit_is_the_defaults). Exit 1 as well when the fitted
// decision merges a calibration pair wrong, 2 on bad input.
//
// The CSVs come from `multires_bench --calibration-data` (candidates.csv:
// every refined hypothesis of every pair, its evidence and whether it is
// right against the truth); each file is a sample of its own (the same pair
// aligned by another build has other hypotheses, hence other rivals): the
// fit must hold on every one, merges are counted over all. Only rows marked
// calibration = 1 are read (E5 and HIH pairs, their floor plans, OTHER
// recorded coarser, the negatives, the live fleet's growing maps, the ROS
// maps: bench/calibration.h);
// F5 and KPT4A pairs never are.
//
// The fit: for each point of the grid below, the threshold is set the
// margin above the highest decision value a pair whose best candidate is
// wrong reaches; the point merging the most positives right wins (ties: the
// highest lowest mergeable score, i.e. the most asked of a best candidate
// with no rival, which the data checks least; then the smaller runner-up
// weight, feature weight and distinct shift; then the larger chance weight,
// evidence, floor and feature cap). The margin: MARGIN, or more if leaving a
// site out shows its wrong values rising further above the others'.
#include "CandidatesCsv.h"

#include <multires_map_merge/Decision.h>

#include <tclap/CmdLine.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <exception>
#include <functional>
#include <fstream>
#include <iostream>
#include <limits>
#include <sstream>
#include <thread>
#include <tuple>

using namespace multires_map_merge;

namespace
{
// Safety margin above the highest wrong value, in score units (the decision
// value moves (1 + runner-up weight) times as much as a score, so the margin
// does too: a quarter of the confidence scale). The least margin: the
// leave-one-site-out overshoot raises it.
constexpr double kMargin = 0.05;
// The grid. No floor above 0.25: right best candidates score about 0.3-0.6,
// and a floor above a pair's score silences its rivals, however close. No
// distinct shift above 40 coarse cells: at 5 cm, 2 m, the displacement the
// benchmark still calls right; a candidate farther away places the map
// elsewhere and must stay a rival.
const std::vector<double> kChanceWeights{0.5, 1.0, 1.5};
const std::vector<double> kEvidence{200, 300, 400, 600, 1000};
const std::vector<std::pair<double, double>> kFeatureTerms{{0.0, 20},  {0.1, 10}, {0.1, 20}, {0.1, 40}, {0.2, 10},
														   {0.2, 20},  {0.2, 40}, {0.4, 10}, {0.4, 20}, {0.4, 40}};
const std::vector<double> kRunnerUpWeights{0.0, 1.0, 2.0, 3.0, 4.0, 6.0, 10.0};
const std::vector<double> kFloors{-0.5, 0.0, 0.25};
const std::vector<double> kDistinctShifts{20.0, 30.0, 40.0};
constexpr size_t kTopFits = 20;
// A live-fleet pair's best candidate off by more than 2 coarse cells (not
// right) but at most this many is the right placement slid along a corridor
// of a barely grown map (the finish refines it on every cell): neither right
// nor wrong here. Farther ones are wrong.
constexpr double kLiveNearCells = 5.0;
// Leave-one-site-out groups, in the table's order: the calibration sites,
// then the sources of pairs (candidates.csv's site) grouped on their own.
const std::vector<std::string> kCalibrationSites{"E5", "HIH"};
const std::vector<std::string> kOwnGroups{"carmen", "live", "ros"};
const std::vector<std::string> kGroups = [] {
	std::vector<std::string> groups = kCalibrationSites;
	groups.insert(groups.end(), kOwnGroups.begin(), kOwnGroups.end());
	return groups;
}();

enum class Kind
{
	positive,  //!< same place: merges counted
	live,  //!< the live fleet's same-building pairs: weigh only where their best is wrong
	negative
};

/** A calibration pair as the fit reads it. */
struct FitPair
{
	CandidatePair pair;
	size_t sample = 0;  //!< index of its file
	Kind kind = Kind::negative;
	unsigned groups = 0;  //!< bit g: touches kGroups[g]
	std::vector<bool> wrong;  //!< per candidate: wrong when decided on (neither right nor near)
};

unsigned groupsOf(const CandidatePair& p)
{
	auto bit = [](const std::string& group) {
		const auto it = std::find(kGroups.begin(), kGroups.end(), group);
		return it == kGroups.end() ? 0u : 1u << (it - kGroups.begin());
	};
	if (std::find(kOwnGroups.begin(), kOwnGroups.end(), p.site) != kOwnGroups.end()) return bit(p.site);
	// A Halmstad pair touches the calibration sites its maps are of.
	auto siteOf = [](const std::string& map) { return map.substr(0, map.find('_')); };
	const unsigned touched = bit(siteOf(p.ref)) | bit(siteOf(p.other));
	return touched & ((1u << kCalibrationSites.size()) - 1);
}

bool isNear(const CandidatePair& p, size_t i)
{
	return p.site == "live" && !p.right[i] && std::isfinite(p.error[i]) && p.error[i] <= kLiveNearCells;
}

/** The calibration pairs of every sample. */
std::vector<FitPair> loadCalibrationPairs(const std::vector<std::string>& paths, size_t& candidates)
{
	std::vector<FitPair> out;
	candidates = 0;
	for (size_t s = 0; s < paths.size(); ++s)
	{
		for (CandidatePair& p : loadCandidatePairs(paths[s]))
		{
			if (!p.calibration) continue;
			FitPair f;
			f.sample = s;
			f.kind = !p.positive ? Kind::negative : p.site == "live" ? Kind::live : Kind::positive;
			f.groups = groupsOf(p);
			for (size_t i = 0; i < p.candidates.size(); ++i) f.wrong.push_back(!p.right[i] && !isNear(p, i));
			candidates += p.candidates.size();
			f.pair = std::move(p);
			out.push_back(std::move(f));
		}
	}
	return out;
}

/** Every point of the grid (threshold unset). */
std::vector<DecisionParams> grid()
{
	std::vector<DecisionParams> points;
	for (double w : kChanceWeights)
		for (double e : kEvidence)
			for (const auto& [fw, cap] : kFeatureTerms)
				for (double k : kRunnerUpWeights)
					for (double floor : kFloors)
						for (double ds : kDistinctShifts)
						{
							DecisionParams p;
							p.chance_weight = w, p.evidence = e, p.feature_weight = fw, p.feature_cap = cap;
							p.runner_up_weight = k, p.runner_up_floor = floor, p.distinct_shift = ds;
							points.push_back(p);
						}
	return points;
}

/** What the decision says of a pair's best candidate (the one decided on
 * by its walls). */
struct Outcome
{
	bool decided = false;  //!< a best candidate exists
	bool right = false, wrong = false;
	double value = -std::numeric_limits<double>::infinity();
};

std::vector<Outcome> outcomesOf(const std::vector<FitPair>& pairs, const DecisionParams& params)
{
	std::vector<Outcome> out(pairs.size());
	for (size_t i = 0; i < pairs.size(); ++i)
	{
		const Decision d = decide(pairs[i].pair.candidates, params);
		if (d.best) out[i] = {true, pairs[i].pair.right[*d.best], pairs[i].wrong[*d.best], d.value};
	}
	return out;
}

/** Which pairs a fit or a judgement reads. */
using Subset = std::vector<char>;

struct Judgement
{
	size_t merged_right = 0, live_right = 0, merged_wrong = 0;
	double highest_wrong = -std::numeric_limits<double>::infinity();
};

/** Merged on the walls: the best candidate's value at the threshold. */
Judgement judge(const std::vector<FitPair>& pairs, const std::vector<Outcome>& outcomes, const Subset& in,
				double threshold)
{
	Judgement j;
	for (size_t i = 0; i < pairs.size(); ++i)
	{
		const Outcome& o = outcomes[i];
		if (!in[i] || !o.decided) continue;
		const bool merged = o.value >= threshold;
		if (o.wrong)
		{
			j.highest_wrong = std::max(j.highest_wrong, o.value);
			j.merged_wrong += merged;
		}
		else if (merged && o.right)
		{
			j.merged_right += pairs[i].kind == Kind::positive;
			j.live_right += pairs[i].kind == Kind::live;
		}
	}
	return j;
}

struct Fit
{
	DecisionParams params;  //!< with the threshold set
	double highest_wrong = 0;
	size_t merged_right = 0, live_right = 0;
};

Fit fitOn(const std::vector<FitPair>& pairs, const std::vector<Outcome>& outcomes, const Subset& in,
		  DecisionParams params, double margin)
{
	const double highest_wrong = judge(pairs, outcomes, in, std::numeric_limits<double>::infinity()).highest_wrong;
	params.threshold = highest_wrong + margin * (1 + params.runner_up_weight);
	const Judgement j = judge(pairs, outcomes, in, params.threshold);
	return {params, highest_wrong, j.merged_right, j.live_right};
}

/** The order of fits, best first (see the file's head). */
bool better(const Fit& a, const Fit& b)
{
	auto key = [](const Fit& f) {
		const DecisionParams& p = f.params;
		return std::make_tuple(f.merged_right, std::round(p.lowestMergeableScore() * 1000), -p.runner_up_weight,
							   -p.feature_weight, -p.distinct_shift, p.chance_weight, p.evidence, p.runner_up_floor,
							   p.feature_cap);
	};
	return key(a) > key(b);
}

Subset subsetOf(const std::vector<FitPair>& pairs, int group, bool touching)
{
	Subset in(pairs.size());
	for (size_t i = 0; i < pairs.size(); ++i)
		in[i] = group < 0 || (((pairs[i].groups >> group) & 1u) != 0) == touching;
	return in;
}

/** The subsets the grid is fitted on: everything, then each group left out. */
constexpr size_t kEverything = 0;
size_t withoutGroup(size_t g) { return 1 + g; }
std::vector<Subset> fitSubsets(const std::vector<FitPair>& pairs)
{
	std::vector<Subset> subsets{subsetOf(pairs, -1, true)};
	for (size_t g = 0; g < kGroups.size(); ++g) subsets.push_back(subsetOf(pairs, int(g), false));
	return subsets;
}

/** Every grid point fitted on each subset, best first per subset; the
 * decisions made once per point, in parallel. */
std::vector<std::vector<Fit>> fitGrid(const std::vector<FitPair>& pairs, const std::vector<Subset>& subsets,
									  double margin)
{
	const std::vector<DecisionParams> points = grid();
	std::vector<std::vector<Fit>> fits(subsets.size(), std::vector<Fit>(points.size()));
	std::atomic<size_t> next{0};
	std::vector<std::exception_ptr> failed(std::max(1u, std::thread::hardware_concurrency()));
	auto work = [&](std::exception_ptr& failure) {
		try
		{
			for (size_t m; (m = next++) < points.size();)
			{
				const std::vector<Outcome> outcomes = outcomesOf(pairs, points[m]);
				for (size_t s = 0; s < subsets.size(); ++s)
					fits[s][m] = fitOn(pairs, outcomes, subsets[s], points[m], margin);
			}
		}
		catch (...)
		{
			failure = std::current_exception();
			next = points.size();
		}
	};
	std::vector<std::thread> threads;
	for (auto& failure : failed) threads.emplace_back(work, std::ref(failure));
	for (auto& t : threads) t.join();
	for (const auto& failure : failed)
		if (failure) std::rethrow_exception(failure);
	for (auto& f : fits) std::sort(f.begin(), f.end(), better);
	return fits;
}

size_t countOf(const std::vector<FitPair>& pairs, const Subset& in, Kind kind)
{
	size_t n = 0;
	for (size_t i = 0; i < pairs.size(); ++i) n += in[i] && pairs[i].kind == kind;
	return n;
}

std::string text(double v)
{
	std::ostringstream out;
	out << v;
	return out.str();
}

std::string fixed3(double v)
{
	char digits[32];
	std::snprintf(digits, sizeof digits, "%.3f", v);
	return digits;
}

std::string describe(const Fit& f)
{
	const DecisionParams& p = f.params;
	char line[300];
	std::snprintf(line, sizeof line,
				  "chance_weight %4.2f evidence %4.0f features %3.1f/%2.0f runner_up_weight %4.1f floor %5.2f "
				  "distinct %2.0f: highest wrong %.3f, threshold %.3f, merged right %zu, live %zu",
				  p.chance_weight, p.evidence, p.feature_weight, p.feature_cap, p.runner_up_weight, p.runner_up_floor,
				  p.distinct_shift, f.highest_wrong, p.threshold, f.merged_right, f.live_right);
	return line;
}

std::string modelOf(const DecisionParams& p)
{
	std::ostringstream out;
	out << p.chance_weight << ", " << p.evidence << ", " << p.feature_weight << "/" << p.feature_cap << ", "
		<< p.runner_up_weight << ", " << p.runner_up_floor << ", " << p.distinct_shift;
	return out.str();
}

/** The fits, best first: every one, or the best for each runner-up weight
 * and the kTopFits best. */
void printFits(const std::vector<Fit>& fits, bool every)
{
	if (every)
	{
		std::cout << "every fit tried:\n";
		for (const Fit& f : fits) std::cout << "  " << describe(f) << "\n";
		return;
	}
	std::cout << "the best fit for each runner-up weight:\n";
	for (double k : kRunnerUpWeights)
	{
		const auto best = std::find_if(
			fits.begin(), fits.end(), [k](const Fit& f) { return f.params.runner_up_weight == k; });
		if (best != fits.end()) std::cout << "  " << describe(*best) << "\n";
	}
	std::cout << "the " << kTopFits << " best fits (of " << fits.size() << "; --all prints every one):\n";
	for (size_t i = 0; i < std::min(kTopFits, fits.size()); ++i) std::cout << "  " << describe(fits[i]) << "\n";
}

/** Leave one site out, as Markdown; returns the largest overshoot. Per
 * group, fitted on the pairs that do not touch it and judged on those that
 * do, two ways: the whole fit made again (how well the fitting generalizes),
 * and `chosen`'s model with only its threshold set again (how far a new
 * site's wrong values rise above the others': the margin's validation). */
double leaveOneSiteOut(const std::vector<FitPair>& pairs, const std::vector<std::vector<Fit>>& fits,
					   const Fit& chosen, std::ostream& table)
{
	table << "| left out | pairs fitted on | its positive pairs | its negative pairs "
			 "| refit: model (chance w., evidence, features, runner-up w., floor, distinct) | merged right | merged wrong "
			 "| this model: threshold | merged right | merged wrong | highest wrong value, fitted / left out "
			 "| overshoot [score units] |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n";
	const std::vector<Outcome> chosen_outcomes = outcomesOf(pairs, chosen.params);
	double overshoot = 0;
	for (size_t g = 0; g < kGroups.size(); ++g)
	{
		const Subset train = subsetOf(pairs, int(g), false), test = subsetOf(pairs, int(g), true);
		// A group the data lacks, or all the data holds, cannot be left out.
		const size_t n_train = std::count(train.begin(), train.end(), 1);
		if (n_train == 0 || n_train == pairs.size()) continue;
		const Fit& refit = fits[withoutGroup(g)].front();
		const Judgement by_refit = judge(pairs, outcomesOf(pairs, refit.params), test, refit.params.threshold);
		const double train_highest = judge(pairs, chosen_outcomes, train, std::numeric_limits<double>::infinity()).highest_wrong;
		const double threshold = train_highest + kMargin * (1 + chosen.params.runner_up_weight);
		const Judgement by_chosen = judge(pairs, chosen_outcomes, test, threshold);
		const double over = (by_chosen.highest_wrong - train_highest) / (1 + chosen.params.runner_up_weight);
		overshoot = std::max(overshoot, over);
		const size_t positives = countOf(pairs, test, Kind::positive), negatives = countOf(pairs, test, Kind::negative);
		char over_text[16];
		std::snprintf(over_text, sizeof over_text, "%+.3f", over);
		table << "| " << kGroups[g] << " | " << n_train << " | " << positives
			  << " | " << negatives << " | " << modelOf(refit.params) << " | " << by_refit.merged_right << " / "
			  << positives << " | " << by_refit.merged_wrong << " | " << fixed3(threshold) << " | "
			  << by_chosen.merged_right << " / " << positives << " | " << by_chosen.merged_wrong << " | "
			  << fixed3(train_highest) << " / " << fixed3(by_chosen.highest_wrong) << " | " << over_text << " |\n";
	}
	return overshoot;
}

/** The fitted numbers, as the aligner's ini reads them (decisionParamFields). */
std::string iniOf(const DecisionParams& p)
{
	std::ostringstream ini;
	ini << "[aligner]\n";
	for (const auto& f : decisionParamFields())
		if (f.member != &DecisionParams::min_confidence)
			ini << f.key << " = " << (f.member == &DecisionParams::threshold ? fixed3(p.*f.member)
																			  : text(p.*f.member))
				<< "\n";
	return ini.str();
}

/** Fitted numbers the aligner's defaults do not hold (to the printed precision). */
std::vector<std::string> differencesFromDefaults(const DecisionParams& fit)
{
	const DecisionParams defaults;
	std::vector<std::string> differ;
	for (const auto& f : decisionParamFields())
		if (f.member != &DecisionParams::min_confidence && !(std::abs(fit.*f.member - defaults.*f.member) <= 5e-4))
			differ.push_back(std::string(f.key) + " fitted " + text(fit.*f.member) + ", default " +
							 text(defaults.*f.member));
	return differ;
}

/** What the fitted decision merges, as the aligner decides it (the exact
 * path too, which no fitted number moves), per sample; the count of wrong
 * merges. */
size_t reportMerges(const std::vector<FitPair>& pairs, const std::vector<std::string>& paths,
					const DecisionParams& params)
{
	std::vector<size_t> positives(paths.size()), right(paths.size()), reported(paths.size()),
		reported_right(paths.size());
	size_t by_cells = 0, wrong = 0, live = 0, live_right = 0, all_right = 0;
	for (const FitPair& f : pairs)
	{
		const Decision d = decide(f.pair.candidates, params);
		const bool merged_right = d.merged && f.pair.right[*d.chosen];
		wrong += d.merged && f.wrong[*d.chosen];
		if (f.kind == Kind::live) live += 1, live_right += merged_right;
		if (f.kind != Kind::positive) continue;
		// The report's order: sensor pairs with the later map as REF.
		const bool in_report = f.pair.ref > f.pair.other && f.pair.ref.find("_layout") == std::string::npos;
		positives[f.sample] += 1, right[f.sample] += merged_right, all_right += merged_right;
		reported[f.sample] += in_report, reported_right[f.sample] += in_report && merged_right;
		by_cells += merged_right && d.by_cells;
	}
	size_t all_positives = 0;
	for (size_t n : positives) all_positives += n;
	std::cout << "# the fitted decision (decide(), as the aligner runs it): " << all_right << "/" << all_positives
			  << " positive pairs merged right (" << by_cells << " on coinciding cells, which no fitted number moves), "
			  << wrong << " merged wrong; live fleet pairs merged right " << live_right << "/" << live << "\n";
	for (size_t s = 0; s < paths.size(); ++s)
		std::cout << "#   " << paths[s] << ": " << right[s] << "/" << positives[s] << " positive pairs merged right, "
				  << reported_right[s] << "/" << reported[s]
				  << " sensor pairs with the later map as REF (the report's order)\n";
	return wrong;
}
}  // namespace

int main(int argc, char** argv)
{
	try
	{
		TCLAP::CmdLine cmd("Fits the aligner's decision on calibration candidates, validated leave one site out",
						   ' ', "1.0");
		TCLAP::UnlabeledMultiArg<std::string> csv_arg(
			"candidates", "candidates.csv files (multires_bench --calibration-data), each a sample", true, "FILE", cmd);
		TCLAP::ValueArg<std::string> markdown_arg("", "markdown", "also write the leave-one-site-out table here",
												  false, "", "FILE", cmd);
		TCLAP::SwitchArg all_arg("", "all", "print every fit tried", cmd);
		TCLAP::SwitchArg defaults_arg("", "expect-defaults", "exit 1 unless the fit is the aligner's defaults", cmd);
		cmd.parse(argc, argv);
		const std::vector<std::string>& paths = csv_arg.getValue();

		size_t candidates = 0;
		const std::vector<FitPair> pairs = loadCalibrationPairs(paths, candidates);
		const Subset everything = subsetOf(pairs, -1, true);
		// The threshold is set by the wrong pairs, and the fit ranked by the right ones.
		if (!countOf(pairs, everything, Kind::negative) || !countOf(pairs, everything, Kind::positive))
			throw std::runtime_error("the calibration pairs (calibration = 1) hold no negative or no positive pair");
		size_t reachable = 0;
		for (const FitPair& f : pairs)
			reachable += f.kind == Kind::positive &&
				std::find(f.pair.right.begin(), f.pair.right.end(), true) != f.pair.right.end();
		std::cout << "calibration data: " << candidates << " candidates, " << countOf(pairs, everything, Kind::positive)
				  << " positive pairs (" << reachable << " with a right candidate), "
				  << countOf(pairs, everything, Kind::live) << " live-fleet same-building pairs, "
				  << countOf(pairs, everything, Kind::negative) << " negative pairs\n";

		// The model fitted with the least margin, on everything and without
		// each group; its margin validated leave one site out; the fit made
		// again with that margin.
		const std::vector<std::vector<Fit>> fits = fitGrid(pairs, fitSubsets(pairs), kMargin);
		std::ostringstream table;
		const double overshoot = leaveOneSiteOut(pairs, fits, fits[kEverything].front(), table);
		const double margin = std::max(kMargin, overshoot);
		char tail[200];
		std::snprintf(tail, sizeof tail,
					  "\nLargest overshoot of this model: %+.3f; the margin above the highest wrong value is max(%g, "
					  "overshoot) = **%.3f** score units.\n",
					  overshoot, kMargin, margin);
		table << tail;
		std::cout << "leave-one-site-out (each group fitted without it, judged on it):\n" << table.str() << "\n";
		if (markdown_arg.isSet() && !(std::ofstream(markdown_arg.getValue()) << table.str()))
			throw std::runtime_error(markdown_arg.getValue() + ": cannot be written");

		const std::vector<Fit> final_fits =
			margin > kMargin ? fitGrid(pairs, {everything}, margin)[0] : fits[kEverything];
		printFits(final_fits, all_arg.getValue());
		const Fit& top = final_fits.front();
		if (!std::isfinite(top.highest_wrong))
			throw std::runtime_error("no calibration pair's best candidate is wrong: nothing sets the threshold");
		DecisionParams best = top.params;
		best.threshold = std::round(best.threshold * 1000) / 1000;  // as the ini holds it
		std::cout << "\n" << iniOf(best) << "# threshold: the margin " << fixed3(margin)
				  << " x (1 + runner-up weight) above the highest wrong value, " << fixed3(top.highest_wrong) << "\n";
		const size_t wrong = reportMerges(pairs, paths, best);
		if (wrong)
		{
			std::cerr << "decision-fit: the fitted decision merges " << wrong << " calibration pairs wrong\n";
			return 1;
		}
		if (defaults_arg.getValue())
		{
			const std::vector<std::string> differ = differencesFromDefaults(best);
			for (const std::string& d : differ) std::cerr << "decision-fit: the fit is not the default: " << d << "\n";
			if (!differ.empty()) return 1;
			std::cout << "# the fit is the aligner's defaults\n";
		}
		return 0;
	}
	catch (const TCLAP::ArgException& e)
	{
		std::cerr << "decision-fit: " << e.argId() << ": " << e.error() << "\n";
	}
	catch (const std::exception& e)
	{
		std::cerr << "decision-fit: " << e.what() << "\n";
	}
	return 2;
}
