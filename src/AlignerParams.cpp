// The aligner's parameters: one list (key, member, range, meaning) that
// loading, saving, validation, the ROS keys and docs/parameters.md's table all read.
#include <multires_map_merge/AlignerParams.h>

#include "ParamText.h"

#include <mrpt/config/CConfigFileBase.h>
#include <mrpt/core/format.h>

#include <sstream>
#include <stdexcept>
#include <type_traits>

namespace multires_map_merge
{
using P = AlignerParams;
using namespace param_text;

namespace
{
/** Pixels of unknown around each feature level of a cropped map: SIFT finds
 * nothing within 5 pixels of an octave's border, 10 and 20 level pixels at
 * its second and third octaves. */
constexpr int kCroppedLevelFrame = 16;
}  // namespace

const std::vector<AlignerParamField>& alignerParamFields()
{
	constexpr bool off0 = true, no0 = false;
	static const std::vector<AlignerParamField> fields{
		// Preparation (PreparedMap.h)
		{"crop_to_known", &P::crop_to_known, 0, 1, no0,
		 "Prepare each map as the box of its known cells, so unknown padding around it changes nothing (for "
		 "heavily padded files; off: a little more recall on tightly saved ones)"},
		// Features and RANSAC (FeatureHypotheses.h)
		{"pyramid_levels", &P::pyramid_levels, 1, 8, no0, "Resolution levels per map (each halves the cells per axis)"},
		{"feature_max_level_cells", &P::feature_max_level_cells, 4096, 1e10, no0,
		 "Pyramid levels with more cells are not searched for features (bounds SIFT's time and memory)"},
		{"sift_contrast_threshold", &P::sift_contrast_threshold, 0, 1, no0, "SIFT detector's contrast threshold"},
		{"sift_edge_threshold", &P::sift_edge_threshold, 1, 1e3, no0, "SIFT detector's edge threshold"},
		{"ratio_test", &P::ratio_test, 0.1, 1, no0, "Lowe's ratio test for feature matches"},
		{"ransac_threshold", &P::ransac_threshold, 0.1, 100, no0, "RANSAC inlier distance [cells of the reference level]"},
		{"ransac_iterations", &P::ransac_iterations, 1, 1e6, no0, "RANSAC iterations per level pair"},
		{"ransac_min_inliers", &P::ransac_min_inliers, 2, 1e9, no0, "Fewest RANSAC inliers for a hypothesis"},
		{"hypotheses_per_level_pair", &P::hypotheses_per_level_pair, 1, 100, no0,
		 "RANSAC re-runs per level pair on the matches left"},
		{"max_hypotheses", &P::max_hypotheses, 1, 1000, no0, "Hypotheses refined by TsICP, most inliers first"},
		{"structure_search", &P::structure_search, 0, 1, no0,
		 "Also try hypotheses from the walls' directions and FFT correlation, unless a candidate is merged whatever comes"},
		{"exhaustive_search", &P::exhaustive_search, 0, 1, no0,
		 "Refine every hypothesis, always search the structure and check the mirror image (calibration data)"},
		{"mirror_check", &P::mirror_check, 0, 1, no0,
		 "Before merging on the walls, align the other map to the reference mirrored too: its candidates are "
		 "rivals, so a mirror image is refused"},
		{"both_orders", &P::both_orders, 0, 1, no0,
		 "A pair refused one way round is aligned the other way round too (REF onto OTHER) and merged if that is "
		 "confident"},
		// TsICP (TsICP.h)
		{"xi_min", &P::xi_min, 0.05, 1, no0, "TsICP: the smallest overlap share it may choose"},
		{"lambda", &P::lambda, 0, 100, no0, "TsICP: overlap preference, psi = e/xi^(1+lambda)"},
		{"icp_max_iterations", &P::icp_max_iterations, 1, 1e5, no0, "TsICP iteration limit"},
		{"icp_relative_tolerance", &P::icp_relative_tolerance, 0, 1, no0, "TsICP stops below this relative gain"},
		{"icp_coarse_points", &P::icp_coarse_points, 0, 1e9, no0,
		 "TsICP converges on about this many of the fixed map's edge points first, then on all (0: all throughout)"},
		{"screen_points", &P::screen_points, 100, 1e9, off0,
		 "Each hypothesis is first refined and judged on about this many points (0: off)"},
		{"screen_margin", &P::screen_margin, 0, 10, no0,
		 "Dropped there when its score is this far below the least score that can still matter"},
		{"bend_refit_iterations", &P::bend_refit_iterations, 0, 100, no0,
		 "Refits of each refined candidate to its wall tiles' best shifts before it is judged (0: off)"},
		// Finish (Finish.h)
		{"icp_finish_on_occupied", &P::icp_finish_on_occupied, 0, 1, no0,
		 "Finish the decided transform by TsICP on the overlap's occupied cells (maps whose cells coincide)"},
		{"finish_max_shift", &P::finish_max_shift, 0, 100, no0, "A finish moving a wall further is not taken [coarse cells]"},
		{"finish_lattice_step", &P::finish_lattice_step, 0.01, 0.5, off0,
		 "Step of the finish's sub-cell shift of the finer map on the coarser lattice (0: off) [coarse cells]"},
		{"finish_bent_lambda", &P::finish_bent_lambda, 0, 100, no0,
		 "Maps that bend: the decided transform is refit with this lambda, balancing the bends (0: off)"},
		// Evidence (MapAgreement.h)
		{"verify_tolerance", &P::verify_tolerance, 0.5, 50, no0, "Walls this close agree [cells of the finer map, plus one coarse cell less one fine]"},
		{"verify_shift", &P::verify_shift, 1, 1000, no0,
		 "Chance: the transform shifted by this much along each axis [coarse cells]"},
		{"verify_turn_deg", &P::verify_turn_deg, 1, 90, no0, "Chance: the transform turned by this much [deg]"},
		// Metadata and limits
		{"use_resolution_metadata", &P::use_resolution_metadata, 0, 1, no0,
		 "Use the stated resolutions as a prior on the scale"},
		{"metadata_scale_tolerance", &P::metadata_scale_tolerance, 0, 10, no0, "Relative tolerance of that prior"},
		{"max_map_cells", &P::max_map_cells, 64, 1e10, no0, "Larger maps are refused at once (bounds peak memory)"},
	};
	return fields;
}

std::vector<std::string> alignerParamKeys()
{
	std::vector<std::string> keys;
	for (const auto& f : alignerParamFields()) keys.emplace_back(f.key);
	for (const auto& f : decisionParamFields()) keys.emplace_back(f.key);
	return keys;
}

void P::loadFromConfigFile(const mrpt::config::CConfigFileBase& c, const std::string& s)
{
	// Into a copy: a value refused leaves these parameters as they were.
	P read = *this;
	for (const auto& f : alignerParamFields()) readField(read, f.member, c, s, f.key);
	for (const auto& f : decisionParamFields())
		read.decision.*f.member = c.read_double(s, f.key, read.decision.*f.member);
	if (const std::string why = read.invalidReason(); !why.empty()) throw std::invalid_argument("[" + s + "] " + why);
	*this = read;
}

void P::saveToConfigFile(mrpt::config::CConfigFileBase& c, const std::string& s) const
{
	for (const auto& f : alignerParamFields()) writeKey(c, s, f.key, valueText(*this, f.member), f.description);
	for (const auto& f : decisionParamFields()) writeKey(c, s, f.key, exactText(decision.*f.member), f.comment);
}

std::string P::invalidReason() const
{
	for (const auto& f : alignerParamFields())
		if (std::string why = outOfRange(*this, f.member, f.key, f.lo, f.hi, f.zero_turns_off); !why.empty()) return why;
	return decision.invalidReason();
}

std::string alignerParamsMarkdown()
{
	const P defaults;
	std::ostringstream md;
	md << "| key | default | valid | meaning |\n|---|---|---|---|\n";
	for (const auto& f : alignerParamFields())
		md << markdownRow(defaults, f.member, f.key, f.lo, f.hi, f.zero_turns_off, f.description);
	for (const auto& f : decisionParamFields())
		if (std::string(f.key) == "min_confidence")
			md << "| `" << f.key << "` | " << exactText(defaults.decision.*f.member) << " | "
			   << rangeText(f.lo, f.hi, false) << " | " << f.comment << " |\n";
	md << "| `decision_*`, `distinct_shift` | calibrated | | the decision's score, rivals and threshold "
		  "([decision.md](decision.md#parameters)) |\n";
	return md.str();
}

FeatureParams P::featureParams() const
{
	FeatureParams p;
	p.pyramid_levels = pyramid_levels;
	p.max_level_cells = feature_max_level_cells;
	p.sift_contrast_threshold = sift_contrast_threshold;
	p.sift_edge_threshold = sift_edge_threshold;
	p.ratio_test = ratio_test;
	p.ransac_threshold = ransac_threshold;
	p.ransac_iterations = ransac_iterations;
	p.min_inliers = ransac_min_inliers;
	p.hypotheses_per_level_pair = hypotheses_per_level_pair;
	if (crop_to_known)
	{
		// A cropped map is no longer a square of padding: its levels by its
		// longer side, framed (SIFT keeps 5 pixels clear of an octave's
		// border, 2 pixels of the margin at a ×8 level).
		p.levels_by_longer_side = true;
		p.level_frame = kCroppedLevelFrame;
	}
	return p;
}

LatticeShiftParams P::latticeParams() const
{
	LatticeShiftParams p;
	p.step = finish_lattice_step;
	return p;
}

TsICPParams P::icpParams() const
{
	TsICPParams p;
	p.xi_min = xi_min;
	p.lambda = lambda;
	p.max_iterations = icp_max_iterations;
	p.relative_tolerance = icp_relative_tolerance;
	p.coarse_points = icp_coarse_points;
	return p;
}

FinishParams P::finishParams() const
{
	FinishParams p;
	p.icp = icpParams();
	p.on_occupied = icp_finish_on_occupied;
	p.max_shift = finish_max_shift;
	p.lattice = latticeParams();
	p.bent_lambda = finish_bent_lambda;
	return p;
}

}  // namespace multires_map_merge
