// The fleet's parameters: one list (key, member, range, meaning) that
// loading, saving, validation, the ROS nodes and docs/parameters.md's table all read;
// and the tolerances they give a pair and a cycle.
#include <multires_map_merge/FleetParams.h>

#include "ParamText.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace multires_map_merge
{
using F = FleetParams;
using namespace param_text;

const std::vector<FleetParamField>& fleetParamFields()
{
	constexpr bool zero_default = true, no0 = false;
	static const std::vector<FleetParamField> fields{
		{"fleet_threads", &F::threads, 1, 256, zero_default,
		 "Pairs of a fleet aligned at once (0: one per hardware thread)"},
		{"settled_confidence", &F::settled_confidence, 0, 1, no0,
		 "A map placed this surely takes no more pairs; the rest are skipped"},
		{"unsettled_tries", &F::unsettled_tries, 0, 1000, no0,
		 "A placed map less sure than that tries this many more pairs for a surer path"},
		{"second_path_tries", &F::second_path_tries, 0, 1000, no0,
		 "A placed map hanging on one pair (no second path to the reference) tries this many more pairs for one"},
		{"cycle_tolerance_cells", &F::cycle_tolerance_cells, 0.1, 1e4, no0,
		 "Least tolerance of a cycle of pairs before its weakest pair is dropped [coarse cells]"},
		{"cycle_tolerance_per_rmse", &F::cycle_tolerance_per_rmse, 0, 1e3, no0,
		 "A pair's tolerance: this many times its edge RMSE, within the least and the largest"},
		{"cycle_tolerance_max_cells", &F::cycle_tolerance_max_cells, 0.1, 1e4, zero_default,
		 "Largest tolerance (0: the aligner's distinct_shift) [coarse cells]"},
		{"joint_refinement", &F::joint_refinement, 0, 1, no0,
		 "Refine every placement at once from all confident pairs kept (false: each through its one path)"},
	};
	return fields;
}

void F::loadFromConfigFile(const mrpt::config::CConfigFileBase& c, const std::string& s)
{
	// Into a copy: a value refused leaves these parameters as they were.
	F read = *this;
	for (const auto& f : fleetParamFields()) readField(read, f.member, c, s, f.key);
	if (const std::string why = read.invalidReason(); !why.empty()) throw std::invalid_argument("[" + s + "] " + why);
	*this = read;
}

void F::saveToConfigFile(mrpt::config::CConfigFileBase& c, const std::string& s) const
{
	for (const auto& f : fleetParamFields()) writeKey(c, s, f.key, valueText(*this, f.member), f.description);
}

std::string F::invalidReason() const
{
	for (const auto& f : fleetParamFields())
		if (std::string why = outOfRange(*this, f.member, f.key, f.lo, f.hi, f.zero_is_default); !why.empty()) return why;
	return "";
}

std::string fleetParamsMarkdown()
{
	const F defaults;
	std::ostringstream md;
	md << "| key | default | valid | meaning |\n|---|---|---|---|\n";
	for (const auto& f : fleetParamFields())
		md << markdownRow(defaults, f.member, f.key, f.lo, f.hi, f.zero_is_default, f.description);
	return md.str();
}

namespace
{
/** What a pair's precision allows (cycle_tolerance_per_rmse × its edge RMSE), unclamped. */
double byPrecision(const FleetParams& p, const FleetEdge& e)
{
	const double cells = p.cycle_tolerance_per_rmse * e.rmse_coarse_cells;
	return std::isfinite(cells) ? cells : 0.0;
}

/** `cells` within cycle_tolerance_cells and the largest tolerance. */
double withinToleranceBounds(const FleetParams& p, double cells)
{
	return std::clamp(cells, p.cycle_tolerance_cells, std::max(p.cycle_tolerance_cells, p.maxToleranceCells()));
}
}  // namespace

double FleetParams::toleranceOf(const FleetEdge& e) const { return withinToleranceBounds(*this, byPrecision(*this, e)); }

double FleetParams::cycleTolerance(
	const std::vector<int>& cycle, const std::vector<FleetEdge>& edges, const std::vector<double>& coarse_cell) const
{
	// Each pair's error adds to the cycle's closure independently: they add
	// in quadrature (a direct pair and a chain of three bent pairs disagree
	// by about the chain's errors combined, not by one pair's).
	double sum_sq = 0;
	for (int c : cycle)
	{
		const double in_closing_cells = coarse_cell.empty() ? 1.0 : coarse_cell[size_t(c)] / coarse_cell[size_t(cycle[0])];
		sum_sq += std::pow(byPrecision(*this, edges[size_t(c)]) * in_closing_cells, 2);
	}
	return withinToleranceBounds(*this, std::sqrt(sum_sq));
}

FleetParams FleetParams::resolvedFor(const DecisionParams& decision) const
{
	FleetParams p = *this;
	if (!(p.cycle_tolerance_max_cells > 0)) p.cycle_tolerance_max_cells = decision.distinct_shift;
	return p;
}

double FleetParams::maxToleranceCells() const
{
	return cycle_tolerance_max_cells > 0 ? cycle_tolerance_max_cells : DecisionParams{}.distinct_shift;
}

}  // namespace multires_map_merge
