#pragma once
// The decision: whether two maps are merged, and how confidently, from what
// was measured about their refined candidate transforms (MapAgreement.h,
// FeatureHypotheses.h). Pure: no maps, no ICP, no threads. The aligner, the
// benchmark's calibration data, the replay tool (decision-replay) and the
// calibration (decision-fit) call this same code. Specification: docs/decision.md.

#include <multires_map_merge/Similarity2D.h>

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace multires_map_merge
{
/** What was measured about one candidate transform (all as numbers, so one
 * list, evidenceFields(), names them for the JSON, CSV, log and replay). */
struct Evidence
{
	/** T: share of both maps' wall points, moved onto the other's seen space,
	 * that do not land on its clearly free space (MapAgreement.h). */
	double tolerant_consistency = 0;
	/** C: the best T under far perturbations of the transform: what chance
	 * gives in these two maps. */
	double chance_consistency = 0;
	/** B: T with each tile of the moved walls shifted as its neighbours fit
	 * best: as if a smooth SLAM bend were taken out. */
	double bent_consistency = 0;
	double support = 0;  //!< share of wall points near a wall of the other map
	double chance_support = 0;  //!< the best support under the far perturbations
	/** A: of the wall points near a directed wall of the other map, the
	 * share near one running the same way. */
	double wall_alignment = 0;
	/** H: of adjacent tiles of the moved walls, the share whose best small
	 * shifts agree. */
	double shift_coherence = 0;
	/** F: feature matches that the transform takes onto each other. */
	double feature_agreement = 0;
	/** n: wall points judged on seen space, weaker direction (for a
	 * candidate judged on a sample: the count the full judgement would take). */
	double judged_points = 0;
	/** From the cells alone (the maps coincide cell for cell); 0 when they cannot. */
	double exact_confidence = 0;
};

/** One evidence field: its name (JSON key, CSV column, log), whether it is a
 * count, and what it measures. */
struct EvidenceField
{
	const char* name;
	double Evidence::*member;
	bool count;
	const char* meaning;
};
/** Every field of Evidence, in one list: what reports and the replay read. */
const std::array<EvidenceField, 10>& evidenceFields();

/** Where a candidate puts the other map: its transform into the reference's
 * cells and where the other map's wall centroid lands (reference cells). */
struct Placement
{
	Similarity2D cells;
	Eigen::Vector2d other_centre{0, 0};
};

/** Within `cells` coarse cells at the centroid, `turn_deg` and `log_scale`. */
bool samePlacement(const Placement& a, const Placement& b, double cells, double turn_deg, double log_scale);

/** What the decision reads of one candidate. */
struct DecisionCandidate
{
	Evidence evidence;
	Placement placement;
	/** Judged on a sample and dropped there: never chosen, no rival. */
	bool screened = false;
	/** Found with one map mirrored: a rival of every candidate, never chosen. */
	bool mirrored = false;
	/** TsICP's ψ: breaks ties between equally confident candidates. */
	double objective = 0;
};

/** The decision's parameters (calibrated: docs/decision.md). */
struct DecisionParams
{
	/** score = B + chance_weight (B − C) − √(evidence / n) + feature_weight · min(F, cap) / cap */
	double chance_weight = 1.0;
	double evidence = 300;  //!< evidence discount [wall points]
	double feature_weight = 0.2;
	double feature_cap = 10;
	/** value = score + runner_up_weight (score − max(runner_up_floor, best rival's score)) */
	double runner_up_weight = 1.0;
	double runner_up_floor = 0.25;
	/** Candidates whose other-map wall centroids lie more than this many
	 * coarse cells apart (or turned by over distinct_turn_deg, or scaled by
	 * over distinct_scale) are rivals, not one answer: independent maps bend,
	 * so one building's right placement refines to optima 20-35 cells apart
	 * on Halmstad; at most 2 m at 5 cm cells, what the benchmark calls right. */
	double distinct_shift = 40.0;
	/** The decision value at confidence 0.5; ±0.1 (1 + runner_up_weight) spans 0..1. */
	double threshold = 0.782;
	double min_confidence = 0.5;  //!< below it: not merged

	/** Turned by more than this, a candidate is a rival (the far
	 * perturbations' turn: beyond it walls no longer overlap by chance). */
	static constexpr double distinct_turn_deg = 8.0;
	/** Scaled by more than this (relative), a candidate is a rival. */
	static constexpr double distinct_scale = 0.1;
	/** The lead over chance of coinciding cells: the calibration's safety
	 * margin (0.05 score units), a fraction of the least lead of maps that
	 * do coincide (0.13). */
	static constexpr double exact_min_lead = 0.05;
	/** Fewer judged wall points than this is too little overlap to judge. */
	static constexpr double min_judged_points = 40;

	/** Why these values cannot work ("" when they can). */
	std::string invalidReason() const;

	double score(const Evidence& e) const;
	/** The first way to be sure: `e.exact_confidence` (the maps coincide
	 * cell for cell) where that is a peak, 0 where not: the walls' tolerant
	 * consistency, and as much with their bends taken out (the lesser of T
	 * and B), must lead its chance value by exact_min_lead. A map shrunk
	 * into a few dozen cells of another place's corner coincides with it
	 * cell for cell and as well a little away (ros_maps: a 19 m test area at
	 * a tenth of its size in a house, and a care site at a quarter in the
	 * test area: T leads by −0.18 and +0.08), and its tiles, moved as their
	 * neighbours fit best, agree less than unmoved (B < T: nothing coherent
	 * to follow; the lesser leads by −0.49 and −0.05); maps that do coincide
	 * lead by 0.12 or more in every benchmark and calibration pair, on 200
	 * wall points as on 5000. */
	double exactConfidence(const Evidence& e) const;
	bool areRivals(const Placement& a, const Placement& b) const;
	/** Decision value per unit of confidence: 0.2 (1 + runner_up_weight). */
	double valuePerConfidence() const;
	double confidenceOfValue(double value) const;
	/** The lowest score whose decision value can reach the threshold (no
	 * rival above the floor). */
	double lowestMergeableScore() const;
	/** The least score a further candidate needs to matter once the best so
	 * far scores `best_score`: to merge, to beat it, or as a rival to lower
	 * its confidence below 1; never below lowestMergeableScore (rivals of a
	 * marginal best below it are not sought: PairSearch.cpp, screenBar). */
	double relevantScore(double best_score) const;
	/** Merged whatever other candidates come: the maps coincide cell for
	 * cell (exact_confidence ≥ exact_needed), or its score alone reaches the
	 * confidence (a rival scores at most as much; one scoring more would
	 * itself be merged). */
	bool mergedWhateverComes(const DecisionCandidate& c, double exact_needed) const;
};

/** One decision parameter: its ini key (section [aligner]; the ROS
 * parameter of the same name), its member, its valid range and what it sets.
 * Loading, saving and validation read this one list. */
struct DecisionParamField
{
	const char* key;
	double DecisionParams::*member;
	double lo, hi;
	const char* comment;
};
const std::array<DecisionParamField, 9>& decisionParamFields();

/** The pair's decision. */
struct Decision
{
	/** The best-scoring candidate judged in full (not screened, not
	 * mirrored, enough judged points): the one decided on by its walls. */
	std::optional<size_t> best;
	/** The candidate reported: the most confident; at equal confidence the
	 * best-scoring one, then the lowest ψ. None when no candidate is eligible. */
	std::optional<size_t> chosen;
	std::vector<double> scores;  //!< per candidate
	std::vector<double> confidence;  //!< per candidate: exact, and the decision value's for `best`
	/** For `best`: its best distinct rival's score (at least the floor), and
	 * score + runner_up_weight (score − runner_up_score). NaN without `best`. */
	double runner_up_score = std::numeric_limits<double>::quiet_NaN();
	double value = std::numeric_limits<double>::quiet_NaN();
	bool merged = false;  //!< chosen, with confidence ≥ min_confidence
	/** Merged on coinciding cells (a candidate's exactConfidence ≥
	 * min_confidence), whatever the walls' decision value: no fitted number
	 * moves it. */
	bool by_cells = false;
};

Decision decide(const std::vector<DecisionCandidate>& candidates, const DecisionParams& p);

/** Why the decision on the chosen candidate (its evidence) was not to merge:
 * its evidence, and the value against the threshold. */
std::string refusalReasons(const Evidence& chosen, const Decision& d, const DecisionParams& p);

}  // namespace multires_map_merge
