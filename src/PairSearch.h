#pragma once
// The search of one pair of prepared maps (the aligner's steps 3 and 4): each
// hypothesis refined by TsICP (screened on a sample first) and judged, a few
// at once; the candidates and the evidence the decision reads. Internal to
// the aligner: not installed.

#include <multires_map_merge/AlignerParams.h>
#include <multires_map_merge/Candidate.h>
#include <multires_map_merge/PreparedMap.h>

#include <mrpt/system/COutputLogger.h>

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace multires_map_merge::pair_search
{
/** What every step of one pair reads; constant while it runs. */
struct PairContext
{
	const PreparedMap& ref;
	const PreparedMap& other;
	const AlignerParams& options;
	const mrpt::system::COutputLogger& log;
	/** Feature matches of every pyramid level pair: RANSAC's input, and
	 * evidence about each candidate (Evidence::feature_agreement). */
	std::vector<LevelMatches> matches;
	std::optional<double> expected_scale;  //!< with use_resolution_metadata
	TsICPParams icp;
	/** A robot map's walls and a sample of its free space, only when the
	 * other map is a floor plan (a plan says where the building is). */
	PointList ref_walls_and_free, other_walls_and_free;

	/** The points each map is judged on: its walls, and against a floor
	 * plan also a sample of its free space. */
	const PointList& refJudged() const { return ref_walls_and_free.empty() ? ref.edges : ref_walls_and_free; }
	const PointList& otherJudged() const
	{
		return other_walls_and_free.empty() ? other.edges : other_walls_and_free;
	}
	/** Whether both maps are judged on their walls alone (no floor plan). */
	bool judgesWallsAlone() const { return ref_walls_and_free.empty() && other_walls_and_free.empty(); }
	/** A finite transform at a scale allowed (use_resolution_metadata). */
	bool usable(const Similarity2D& t) const;
};

/** The context of a pair; the feature matching is timed as "matches". */
PairContext makeContext(
	const PreparedMap& ref, const PreparedMap& other, const AlignerParams& options,
	const mrpt::system::COutputLogger& log, std::map<std::string, double>& stage_seconds);

/** The evidence about a transform, judged on at most `most` points per map;
 * with fewer than a full judgement takes, the judged count is the one it
 * would take. Wall alignment only `in_full`: a screen never decides. */
struct Judgement
{
	TwoWayShiftField bends;  //!< the tiles' best shifts (what the bend refit follows)
	Evidence evidence;
	double score = 0;
};
Judgement judge(const PairContext& c, const Similarity2D& t, size_t most, bool in_full);

/** A candidate's hypothesis and TsICP result: what the report needs of it. */
struct Refinement
{
	Hypothesis h;
	TsICPResult r;
};

/** The search's state over every hypothesis list of a pair. */
struct SearchState
{
	/** Below this score a hypothesis can neither merge nor, as a rival,
	 * lower the best candidate's confidence (the mirror pass's bar is the
	 * best score found before it). */
	double least_relevant = 0;
	std::vector<Candidate> candidates;  //!< in the order refined
	std::vector<Refinement> refinements;  //!< one per candidate
	/** Candidates whose maps coincide cell for cell: a hypothesis whose
	 * sample refinement lands on one is not refined again. */
	std::vector<Candidate> exact_found;
	size_t hypotheses = 0, hypotheses_refined = 0;
	std::map<std::string, double> stage_seconds;  //!< icp, verify (summed over threads), ransac, structure
};

/** Refines (up to max_hypotheses of) `list` in rounds, adding to `state`. */
void refineAll(const PairContext& c, SearchState& state, const std::vector<Hypothesis>& list);

/** A given start refined: other's grid metric frame → ref's (tracking). */
void refineStart(const PairContext& c, SearchState& state, const Similarity2D& start_metric);
/** RANSAC's hypotheses of every pyramid level pair (timed as "ransac"), refined. */
void refineFeatureHypotheses(const PairContext& c, SearchState& state);
/** The buildings' structure's hypotheses (StructureHypotheses.h; timed as
 * "structure"), refined. */
void refineStructureHypotheses(const PairContext& c, SearchState& state);

/** Before a merge: each candidate the screen stopped that is a rival of
 * `of` (another placement; with none, every one: a mirrored map's
 * candidates are rivals of any) and scored on its sample no more than the
 * screen's margin below the rival floor is refined in full, in place, and
 * judged again. The screen drops a hypothesis that cannot merge; as a rival
 * between the floor and the lowest mergeable score it can still refuse a
 * wrong merge (a half map placed at scale 0.87 on a corridor's start, the
 * right placement screened at 0.35). Only pairs about to merge pay.
 * Returns how many were refined. */
size_t refineScreenedRivals(const PairContext& c, SearchState& state, const std::optional<Placement>& of);

/** The best score of a candidate judged in full (not mirrored); -inf if none. */
double bestScore(const std::vector<Candidate>& candidates);

/** The decision's view of a candidate. */
DecisionCandidate decisionInput(const Candidate& c);
std::vector<DecisionCandidate> decisionInput(const std::vector<Candidate>& candidates);

}  // namespace multires_map_merge::pair_search
