// The decision module on fixed evidence: no maps, no ICP. What the aligner,
// the benchmark and decision-replay and decision-fit all call.
#include <multires_map_merge/CScalingGridMapAligner.h>
#include <multires_map_merge/Decision.h>

#include <gtest/gtest.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/config/CConfigFileMemory.h>

#include <cmath>
#include <set>
#include <string>

using namespace multires_map_merge;

namespace
{
/** Walls that agree well above chance, run alike and bend smoothly. */
Evidence strongWalls(double bent)
{
	Evidence e;
	e.tolerant_consistency = bent - 0.05;
	e.bent_consistency = bent;
	e.chance_consistency = 0.45;
	e.wall_alignment = 0.85;
	e.shift_coherence = 0.5;
	e.feature_agreement = 10;
	e.judged_points = 4000;
	return e;
}

DecisionCandidate at(const Evidence& e, double x, double yaw_deg = 0, double scale = 1)
{
	DecisionCandidate c;
	c.evidence = e;
	c.placement.cells = Similarity2D(scale, yaw_deg * M_PI / 180, {x, 0});
	c.placement.other_centre = {x, 0};
	return c;
}
}  // namespace

TEST(Decision, ScoreIsTheDocumentedSum)
{
	DecisionParams p;
	const Evidence e = strongWalls(0.9);
	const double expected = 0.9 + p.chance_weight * (0.9 - 0.45) - std::sqrt(p.evidence / 4000) +
		p.feature_weight * std::min(10.0, p.feature_cap) / p.feature_cap;
	EXPECT_DOUBLE_EQ(p.score(e), expected);
	// Fewer judged points prove less; more feature matches than the cap gain nothing.
	Evidence small = e;
	small.judged_points = 100;
	EXPECT_LT(p.score(small), p.score(e));
	Evidence many = e;
	many.feature_agreement = 1000;
	EXPECT_DOUBLE_EQ(p.score(many), p.score(e) + p.feature_weight * (std::min(1000.0, p.feature_cap) - 10) / p.feature_cap);
}

TEST(Decision, ConfidenceIsHalfAtTheThresholdAndStaysInZeroOne)
{
	DecisionParams p;
	EXPECT_DOUBLE_EQ(p.confidenceOfValue(p.threshold), 0.5);
	EXPECT_DOUBLE_EQ(p.confidenceOfValue(p.threshold + 0.5 * p.valuePerConfidence()), 1.0);
	EXPECT_DOUBLE_EQ(p.confidenceOfValue(-100), 0.0);
	EXPECT_DOUBLE_EQ(p.confidenceOfValue(100), 1.0);
}

TEST(Decision, TheBestScoringCandidateIsDecidedAgainstItsBestDistinctRival)
{
	DecisionParams p;
	// Walls agreeing moderately, no feature matches: confidence below 1.
	auto moderate = [](double bent) {
		Evidence e = strongWalls(bent);
		e.feature_agreement = 0;
		return e;
	};
	const DecisionCandidate best = at(moderate(0.62), 0);
	// A rival far away (a placement elsewhere) and a near twin (the same
	// placement, a bend apart): only the rival lowers the decision value.
	const DecisionCandidate rival = at(moderate(0.6), 10 * p.distinct_shift);
	const DecisionCandidate twin = at(moderate(0.61), 0.5 * p.distinct_shift);
	const Decision alone = decide({best, twin}, p);
	ASSERT_TRUE(alone.best && alone.chosen);
	EXPECT_EQ(*alone.best, 0u);
	EXPECT_DOUBLE_EQ(alone.runner_up_score, p.runner_up_floor);
	const Decision against = decide({best, twin, rival}, p);
	EXPECT_DOUBLE_EQ(against.runner_up_score, p.score(rival.evidence));
	EXPECT_DOUBLE_EQ(
		against.value, against.scores[0] + p.runner_up_weight * (against.scores[0] - against.runner_up_score));
	EXPECT_LT(against.value, alone.value);
	EXPECT_GT(alone.confidence[0], 0);
	EXPECT_LT(against.confidence[0], alone.confidence[0]);
	// Turned or scaled beyond the bounds, the same centre is a rival too.
	EXPECT_TRUE(p.areRivals(best.placement, at(strongWalls(0.8), 0, 2 * p.distinct_turn_deg).placement));
	EXPECT_TRUE(p.areRivals(best.placement, at(strongWalls(0.8), 0, 0, 1.5).placement));
	EXPECT_FALSE(p.areRivals(best.placement, twin.placement));
}

TEST(Decision, MirroredAndScreenedCandidatesAreNeverChosen)
{
	DecisionParams p;
	// The mirrored other map's candidate at the very same placement: a rival
	// all the same (a map that fits itself mirrored proves nothing by its
	// walls). A screened one scoring higher is neither chosen nor a rival.
	DecisionCandidate mirrored = at(strongWalls(0.95), 0);
	mirrored.mirrored = true;
	DecisionCandidate screened = at(strongWalls(0.99), 1000);
	screened.screened = true;
	const DecisionCandidate right = at(strongWalls(0.9), 0);
	const Decision d = decide({mirrored, screened, right}, p);
	ASSERT_TRUE(d.best && d.chosen);
	EXPECT_EQ(*d.best, 2u);
	EXPECT_EQ(*d.chosen, 2u);
	EXPECT_DOUBLE_EQ(d.runner_up_score, p.score(mirrored.evidence));
	EXPECT_DOUBLE_EQ(decide({screened, right}, p).runner_up_score, p.runner_up_floor);
	EXPECT_LT(d.value, decide({right}, p).value);
}

// Maps that coincide cell for cell are merged on that alone, whatever the
// walls score (a small overlap pays a large evidence discount), but only
// where that is a peak: the cells of a map shrunk into a few dozen of
// another place's agree as well a little away.
TEST(Decision, CellsCoincidingMergeOnlyWhereTheyStandAboveChance)
{
	DecisionParams p;
	Evidence peak;
	peak.tolerant_consistency = peak.bent_consistency = 0.99;
	peak.chance_consistency = 0.99 - DecisionParams::exact_min_lead;
	peak.judged_points = 200;  // walls alone would never merge on so few
	peak.exact_confidence = 0.9;
	Evidence flat = peak;
	flat.chance_consistency = 0.99 - 0.9 * DecisionParams::exact_min_lead;
	// The lead must hold with the bends taken out: tiles of a lucky overlap,
	// moved as their neighbours fit best, agree less than unmoved.
	Evidence unbent = peak;
	unbent.bent_consistency = peak.chance_consistency + 0.9 * DecisionParams::exact_min_lead;
	EXPECT_EQ(p.exactConfidence(peak), 0.9);
	EXPECT_EQ(p.exactConfidence(flat), 0);
	EXPECT_EQ(p.exactConfidence(unbent), 0);
	const Decision on_peak = decide({at(peak, 0)}, p), on_flat = decide({at(flat, 0)}, p);
	EXPECT_LT(on_peak.value, p.threshold) << "the walls' evidence is too little";
	EXPECT_TRUE(on_peak.merged);
	EXPECT_DOUBLE_EQ(on_peak.confidence[0], 0.9);
	EXPECT_FALSE(on_flat.merged);
	EXPECT_TRUE(p.mergedWhateverComes(at(peak, 0), 0.5));
	EXPECT_FALSE(p.mergedWhateverComes(at(flat, 0), 0.5));
}

TEST(Decision, OnlyTheScoreAndTheRivalsDecideAndARefusalSaysTheValue)
{
	DecisionParams p;
	const DecisionCandidate good = at(strongWalls(0.9), 0);
	const Decision merged = decide({good}, p);
	ASSERT_TRUE(merged.merged);
	// Walls that agree no better than chance lose the score's lead term, by
	// chance_weight (1 + runner_up_weight) per unit of chance; moderate walls
	// that fit as well anywhere are refused, and the refusal gives the value
	// against the threshold.
	DecisionCandidate chance = good;
	chance.evidence.chance_consistency = chance.evidence.bent_consistency;
	EXPECT_NEAR(decide({chance}, p).value,
				merged.value - p.chance_weight * (1 + p.runner_up_weight) * (0.9 - 0.45), 1e-12);
	DecisionCandidate moderate = at(strongWalls(0.6), 0);
	moderate.evidence.chance_consistency = 0.6;
	moderate.evidence.feature_agreement = 0;
	const Decision d_chance = decide({moderate}, p);
	EXPECT_FALSE(d_chance.merged);
	EXPECT_LT(d_chance.value, p.threshold);
	const std::string why = refusalReasons(moderate.evidence, d_chance, p);
	EXPECT_NE(why.find("decision value"), std::string::npos) << why;
	EXPECT_NE(why.find("by chance"), std::string::npos) << why;
	// Wall alignment and shift coherence are reported, not decided on: no
	// gate (a feature that needs one to be safe is the wrong feature).
	DecisionCandidate crossing = good;
	crossing.evidence.wall_alignment = 0.1;
	crossing.evidence.shift_coherence = 0.0;
	const Decision d_crossing = decide({crossing}, p);
	EXPECT_TRUE(d_crossing.merged);
	EXPECT_DOUBLE_EQ(d_crossing.value, merged.value);
	// Too few judged points: not decided on its walls at all.
	DecisionCandidate tiny = good;
	tiny.evidence.judged_points = DecisionParams::min_judged_points - 1;
	const Decision d = decide({tiny}, p);
	EXPECT_FALSE(d.best);
	EXPECT_FALSE(d.merged);
	// Coinciding cells merge whatever the walls' score.
	tiny.evidence.exact_confidence = 0.9;
	EXPECT_TRUE(decide({tiny}, p).merged);
}

TEST(Decision, EvidenceAndParameterListsNameEveryFieldOnce)
{
	// Every member once: set each through the list to a value of its own.
	std::set<std::string> names;
	Evidence e;
	for (size_t i = 0; i < evidenceFields().size(); ++i) e.*evidenceFields()[i].member = double(i + 1);
	std::set<double> values;
	for (const auto& f : evidenceFields()) names.insert(f.name), values.insert(e.*f.member);
	EXPECT_EQ(names.size(), evidenceFields().size());
	EXPECT_EQ(values.size(), evidenceFields().size());
	EXPECT_EQ(sizeof(Evidence), evidenceFields().size() * sizeof(double)) << "a field missing from evidenceFields()";

	const DecisionParams defaults;
	EXPECT_EQ(defaults.invalidReason(), "");
	std::set<std::string> keys;
	for (const auto& f : decisionParamFields()) keys.insert(f.key);
	EXPECT_EQ(keys.size(), decisionParamFields().size());
	// Saved to an ini file and loaded by its keys, every value comes back
	// exactly (a third is no short decimal); one out of range is named.
	CScalingGridMapAligner::TConfigParams a;
	for (const auto& f : decisionParamFields()) a.decision.*f.member = f.lo + std::min(f.hi - f.lo, 2.0) / 3;
	a.icp_relative_tolerance = 1e-7;  // MRPT's own "%f" would save it as 0
	const std::string path = ::testing::TempDir() + "/decision_roundtrip.ini";
	{
		mrpt::config::CConfigFile out(path);
		a.saveToConfigFile(out, "aligner");
	}
	CScalingGridMapAligner::TConfigParams b;
	b.loadFromConfigFile(mrpt::config::CConfigFile(path), "aligner");
	for (const auto& f : decisionParamFields()) EXPECT_EQ(b.decision.*f.member, a.decision.*f.member) << f.key;
	EXPECT_EQ(b.icp_relative_tolerance, 1e-7);
	mrpt::config::CConfigFileMemory bad;
	bad.write("aligner", "decision_runner_up_floor", 20.0);
	CScalingGridMapAligner::TConfigParams c;
	try
	{
		c.loadFromConfigFile(bad, "aligner");
		ADD_FAILURE() << "decision_runner_up_floor 20 was taken";
	}
	catch (const std::invalid_argument& e)
	{
		EXPECT_NE(std::string(e.what()).find("decision_runner_up_floor"), std::string::npos) << e.what();
	}
	// A refused file leaves the parameters as they were.
	EXPECT_EQ(c.decision.runner_up_floor, DecisionParams().runner_up_floor);
}
