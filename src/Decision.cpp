#include <multires_map_merge/Decision.h>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace multires_map_merge
{
const std::array<EvidenceField, 10>& evidenceFields()
{
	static const std::array<EvidenceField, 10> fields{{
		{"tolerant_consistency", &Evidence::tolerant_consistency, false,
		 "T: share of wall points moved onto seen space not landing on free space"},
		{"chance_consistency", &Evidence::chance_consistency, false, "C: the best T under far perturbations"},
		{"bent_consistency", &Evidence::bent_consistency, false, "B: T with a smooth bend taken out"},
		{"support", &Evidence::support, false, "share of wall points near a wall of the other map"},
		{"chance_support", &Evidence::chance_support, false, "the best support under far perturbations"},
		{"wall_alignment", &Evidence::wall_alignment, false, "A: near walls running the same way"},
		{"shift_coherence", &Evidence::shift_coherence, false, "H: adjacent tiles fitting after alike shifts"},
		{"feature_agreement", &Evidence::feature_agreement, true, "F: feature matches taken onto each other"},
		{"judged", &Evidence::judged_points, true, "n: wall points judged (weaker direction)"},
		{"exact_confidence", &Evidence::exact_confidence, false, "from the cells alone: the maps coincide"},
	}};
	return fields;
}

bool samePlacement(const Placement& a, const Placement& b, double cells, double turn_deg, double log_scale)
{
	const double coarse = std::max({1.0, a.cells.scale, b.cells.scale});
	return (a.other_centre - b.other_centre).norm() <= cells * coarse &&
		std::abs(std::remainder(a.cells.yaw - b.cells.yaw, 2 * M_PI)) <= turn_deg * M_PI / 180 &&
		std::abs(std::log(a.cells.scale / b.cells.scale)) <= log_scale;
}

const std::array<DecisionParamField, 9>& decisionParamFields()
{
	using P = DecisionParams;
	static const std::array<DecisionParamField, 9> fields{{
		{"decision_chance_weight", &P::chance_weight, 0, 10,
		 "Score = B + w (B - chance T) - sqrt(evidence / judged) + feature term"},
		{"decision_evidence", &P::evidence, 0, 1e6, "Evidence discount of small overlaps [wall points]"},
		{"decision_feature_weight", &P::feature_weight, 0, 10, "Score gained at decision_feature_cap agreeing feature matches"},
		{"decision_feature_cap", &P::feature_cap, 1, 1e6, "Agreeing feature matches beyond this gain no more"},
		{"decision_runner_up_weight", &P::runner_up_weight, 0, 100,
		 "Decision value = best score + w (it - best distinct rival's score)"},
		{"decision_runner_up_floor", &P::runner_up_floor, -10, 10, "A rival scoring below this counts as this"},
		{"distinct_shift", &P::distinct_shift, 1, 1e4, "Candidates this far apart are rivals [coarse cells]"},
		{"decision_threshold", &P::threshold, 0, 10, "Decision value at confidence 0.5 (calibrated)"},
		{"min_confidence", &P::min_confidence, 0, 1, "Below this the maps are reported as not merged"},
	}};
	return fields;
}

std::string DecisionParams::invalidReason() const
{
	for (const auto& f : decisionParamFields())
		if (const double v = this->*f.member; !(v >= f.lo && v <= f.hi))
		{
			std::ostringstream why;
			why << f.key << " = " << v << " is outside [" << f.lo << ", " << f.hi << "]";
			return why.str();
		}
	return "";
}

double DecisionParams::score(const Evidence& e) const
{
	const double b = e.bent_consistency;
	return b + chance_weight * (b - e.chance_consistency) - std::sqrt(evidence / std::max(1.0, e.judged_points)) +
		feature_weight * std::min(e.feature_agreement, feature_cap) / feature_cap;
}

double DecisionParams::exactConfidence(const Evidence& e) const
{
	// Cells that coincide have no bend to take out: B is T there. A lucky
	// overlap of a squeezed map loses it when its tiles are moved (B < T).
	const double held = std::min(e.tolerant_consistency, e.bent_consistency);
	return held - e.chance_consistency >= exact_min_lead ? e.exact_confidence : 0.0;
}

bool DecisionParams::areRivals(const Placement& a, const Placement& b) const
{
	return !samePlacement(a, b, distinct_shift, distinct_turn_deg, std::log(1 + distinct_scale));
}

double DecisionParams::valuePerConfidence() const
{
	// Confidence 0.5 at the threshold, rising by 1 over 0.2 (1 + k) of value.
	return 0.2 * (1 + runner_up_weight);
}

double DecisionParams::confidenceOfValue(double value) const
{
	return std::clamp(0.5 + (value - threshold) / valuePerConfidence(), 0.0, 1.0);
}

double DecisionParams::lowestMergeableScore() const
{
	// value = s + k (s − rival) with rival ≥ floor, so value ≥ threshold needs
	// (1 + k) s − k floor ≥ threshold.
	return (threshold + runner_up_weight * runner_up_floor) / (1 + runner_up_weight);
}

double DecisionParams::relevantScore(double best_score) const
{
	// A rival r lowers the confidence of value s + k (s − r) while that is
	// below the value of confidence 1: r > s − (V₁ − s)/k. A better s raises
	// both bounds, so the least relevant score only rises.
	const double k = runner_up_weight;
	if (!(k > 0) || !std::isfinite(best_score)) return lowestMergeableScore();
	const double value_for_certainty = threshold + 0.5 * valuePerConfidence();
	return std::max(lowestMergeableScore(), std::min(best_score, best_score - (value_for_certainty - best_score) / k));
}

bool DecisionParams::mergedWhateverComes(const DecisionCandidate& c, double exact_needed) const
{
	const Evidence& e = c.evidence;
	if (exactConfidence(e) >= exact_needed) return true;
	const double s = score(e);
	return !c.screened && e.judged_points >= min_judged_points && s >= runner_up_floor &&
		confidenceOfValue(s) >= std::max(0.5, min_confidence);
}

namespace
{
/** Judged in full and eligible to be decided on. */
bool decidable(const DecisionCandidate& c)
{
	return !c.screened && !c.mirrored && c.evidence.judged_points >= DecisionParams::min_judged_points;
}
}  // namespace

Decision decide(const std::vector<DecisionCandidate>& cands, const DecisionParams& p)
{
	Decision d;
	const size_t n = cands.size();
	d.scores.resize(n);
	d.confidence.resize(n);
	for (size_t i = 0; i < n; ++i)
	{
		d.scores[i] = p.score(cands[i].evidence);
		d.confidence[i] = p.exactConfidence(cands[i].evidence);
		d.by_cells |= !cands[i].mirrored && d.confidence[i] >= p.min_confidence;
		if (decidable(cands[i]) && (!d.best || d.scores[i] > d.scores[*d.best])) d.best = i;
	}
	// Two ways to be sure: the maps coincide cell for cell (exact_confidence),
	// or the best-scoring candidate's walls agree well above chance and better
	// than any distinct rival's. Screened candidates are no rivals: they scored
	// below the lowest mergeable score less the screen's margin, on a sample.
	if (d.best)
	{
		const size_t b = *d.best;
		d.runner_up_score = p.runner_up_floor;
		for (size_t i = 0; i < n; ++i)
			if (i != b && !cands[i].screened &&
				(cands[i].mirrored || p.areRivals(cands[b].placement, cands[i].placement)))
				d.runner_up_score = std::max(d.runner_up_score, d.scores[i]);
		d.value = d.scores[b] + p.runner_up_weight * (d.scores[b] - d.runner_up_score);
		d.confidence[b] = std::max(d.confidence[b], p.confidenceOfValue(d.value));
	}
	// At equal confidence (none at all, typically) the candidate decided on is
	// reported: a refusal then says why that one was not enough.
	auto before = [&](size_t i, size_t j) {
		if (d.confidence[i] != d.confidence[j]) return d.confidence[i] > d.confidence[j];
		if ((i == d.best) != (j == d.best)) return i == d.best;
		return cands[i].objective < cands[j].objective;
	};
	for (size_t i = 0; i < n; ++i)
		if (!cands[i].mirrored && (!d.chosen || before(i, *d.chosen))) d.chosen = i;
	d.merged = d.chosen && d.confidence[*d.chosen] >= p.min_confidence;
	return d;
}

std::string refusalReasons(const Evidence& e, const Decision& d, const DecisionParams& p)
{
	std::ostringstream why;
	why << "confidence " << (d.chosen ? d.confidence[*d.chosen] : 0.0) << " < " << p.min_confidence
		<< "; tolerant consistency " << e.tolerant_consistency << ", " << e.bent_consistency
		<< " with its bends taken out, against " << e.chance_consistency << " by chance";
	// The value speaks only of the candidate decided on.
	if (!d.chosen || d.chosen != d.best || !std::isfinite(d.value)) return why.str();
	why << ", score " << d.scores[*d.best] << " against " << d.runner_up_score << " for the best rival (decision value "
		<< d.value << ", " << p.threshold << " needed)";
	return why.str();
}

}  // namespace multires_map_merge
