// decision-replay: the aligner's decision (Decision.h) replayed on saved
// candidates, the benchmark's candidates.csv (multires_bench
// --calibration-data), with the default parameters or those of an ini's
// [aligner] section: what a set of decision parameters does, pair by pair,
// without aligning anything again (the fit itself: decision-fit).
//
// Prints one line per pair (CSV): site, ref, other, positive, calibration,
// candidates, merged, right (the chosen candidate is right by the truth),
// error (its error, pixels or coarse cells), confidence, value; then, on
// stderr, per site the merges whose chosen candidate is right and those
// whose is not (a wrong merge, unless the benchmark's rules call its error
// near: decision-fit). Exit 0, or 2 on bad input.
#include "CandidatesCsv.h"

#include <multires_map_merge/CScalingGridMapAligner.h>

#include <mrpt/config/CConfigFile.h>
#include <tclap/CmdLine.h>

#include <cmath>
#include <iostream>
#include <map>

using namespace multires_map_merge;

int main(int argc, char** argv)
{
	try
	{
		TCLAP::CmdLine cmd("Replays the aligner's decision on saved candidates (candidates.csv)", ' ', "1.0");
		TCLAP::UnlabeledValueArg<std::string> csv_arg("candidates", "candidates.csv", true, "", "FILE", cmd);
		TCLAP::ValueArg<std::string> config_arg(
			"", "config", "decision parameters: section [aligner] of an ini file (else the defaults)", false, "",
			"FILE.ini", cmd);
		cmd.parse(argc, argv);
		CScalingGridMapAligner::TConfigParams options;
		if (config_arg.isSet())
			options.loadFromConfigFile(mrpt::config::CConfigFile(config_arg.getValue()), "aligner");
		const DecisionParams& params = options.decision;

		struct Tally
		{
			size_t pairs = 0, positives = 0, right = 0, wrong = 0;
		};
		std::map<std::string, Tally> tally;
		std::cout << "site,ref,other,positive,calibration,candidates,merged,right,error,confidence,value,by_cells\n";
		for (const CandidatePair& p : loadCandidatePairs(csv_arg.getValue()))
		{
			const Decision d = decide(p.candidates, params);
			const bool right = d.chosen && p.positive && p.right[*d.chosen];
			const double error = d.chosen ? p.error[*d.chosen] : std::nan("");
			const double confidence = d.chosen ? d.confidence[*d.chosen] : 0.0;
			std::cout << p.site << "," << p.ref << "," << p.other << "," << p.positive << "," << p.calibration << ","
					  << p.candidates.size() << "," << d.merged << "," << right << "," << error << "," << confidence
					  << "," << d.value << "," << d.by_cells << "\n";
			Tally& t = tally[p.site + (p.calibration ? " (calibration)" : "")];
			++t.pairs;
			t.positives += p.positive;
			t.right += d.merged && right;
			t.wrong += d.merged && !right;
		}
		for (const auto& [site, t] : tally)
			std::cerr << site << ": " << t.pairs << " pairs, " << t.positives << " positive; merged right " << t.right
					  << ", merged with a candidate not right " << t.wrong << "\n";
		return 0;
	}
	catch (const TCLAP::ArgException& e)
	{
		std::cerr << "decision-replay: " << e.argId() << ": " << e.error() << "\n";
	}
	catch (const std::exception& e)
	{
		std::cerr << "decision-replay: " << e.what() << "\n";
	}
	return 2;
}
