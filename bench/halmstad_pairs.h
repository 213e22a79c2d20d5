#pragma once
// Real independent maps (Halmstad Robot Maps, ../shared/data/halmstad): every
// same-site sensor pair judged against the annotation, cross-site negatives,
// MRPT beside on a sample.

#include "context.h"
#include "halmstad.h"
#include "scaling.h"

#include <string>
#include <vector>

namespace multires_bench
{
struct HalmstadRun
{
	std::string site, ref, other;
	bool positive = true;  //!< same site (annotated) or a cross-site negative
	bool calibration = false;  //!< a calibration site's pair (may be tuned on)
	bool merged = false;
	HalmstadOutcome outcome;  //!< of the reported transform (positives)
	double seconds = 0, confidence = 0;
	std::string message;
	LimitedMrpt mrpt;
	bool mrpt_right = false;
	/** A positive not merged right is aligned again with the annotation as
	 * the first hypothesis (then the usual search and decision): merged right
	 * then, the search missed it; refused again, its evidence is too weak. */
	bool retried_from_truth = false;
	bool right_from_truth = false;
};

/** A site's same-site pairs counted as the report states them. */
struct HalmstadTally
{
	size_t pairs = 0, right = 0, refused = 0, wrong = 0;
	std::vector<double> disp, corr, secs;  //!< displacement and corr. RMS of the right merges [px]; every pair's time
	size_t mrpt_ran = 0, mrpt_right = 0, mrpt_timeout = 0;
	/** Of the pairs not merged right: merged right from the annotation (the
	 * search missed them), refused from it too (their evidence is too weak). */
	size_t search_missed = 0, evidence_weak = 0;
	void add(const HalmstadRun& positive);
};

/** Aligns REF ← OTHER from map_server files; for positives judges the result
 * against the annotation. Every candidate goes to ctx.candidates with its
 * features and whether it was right: the data the decision is calibrated on. */
HalmstadRun runHalmstadPair(
	const BenchContext& ctx, const HalmstadData& data, const std::string& ref, const std::string& other,
	const std::string& dir, double mrpt_limit_s = 0);

/** The cross-site negatives of `sites` (REF, OTHER): each of their maps as
 * REF against `per_map` maps of the other sites, spread over every site and
 * map. */
std::vector<std::pair<std::string, std::string>> crossSiteNegatives(
	const HalmstadData& data, const std::vector<std::string>& sites, size_t per_map);

/** The pair sets: every unordered same-site pair (REF = the later
 * map), and cross-site negatives: each map of one site against maps of the
 * others, `negatives_per_map` each. */
std::vector<HalmstadRun> runHalmstad(
	const BenchContext& ctx, const HalmstadData& data, const std::vector<std::string>& sites, size_t negatives_per_map);

}  // namespace multires_bench
