// decision-replay: the aligner's decision (Decision.h) replayed on saved
// candidates, the benchmark's candidates.csv (multires_bench
// --calibration-data), with the default parameters or those of an ini's
// [aligner] section. What the calibration checks a fit with: the decision
// replayed is the aligner's own code, not a second implementation.
//
// Prints one line per pair (CSV): site, ref, other, positive, calibration,
// candidates, merged, right (the chosen candidate is right by the truth),
// error (its error, pixels or coarse cells), confidence, value; then, on
// stderr, per site the merges whose chosen candidate is right and those
// whose is not (a wrong merge, unless the benchmark's rules call its error
// near: scripts/calibrate_decision.py). Exit 0, or 2 on bad input.
#include <multires_map_merge/CScalingGridMapAligner.h>

#include <mrpt/config/CConfigFile.h>
#include <tclap/CmdLine.h>

#include <cmath>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>

using namespace multires_map_merge;

namespace
{
/** One row of candidates.csv, by column name. */
using Row = std::map<std::string, std::string>;

std::vector<std::string> splitCsv(const std::string& line)
{
	std::vector<std::string> cells;
	std::stringstream in(line);
	for (std::string cell; std::getline(in, cell, ',');) cells.push_back(cell);
	return cells;
}

double number(const Row& row, const std::string& column, const std::string& where)
{
	const auto it = row.find(column);
	if (it == row.end()) throw std::runtime_error(where + ": no column '" + column + "'");
	try
	{
		return it->second == "nan" ? std::nan("") : std::stod(it->second);
	}
	catch (const std::exception&)
	{
		throw std::runtime_error(where + ": column '" + column + "' is not a number: '" + it->second + "'");
	}
}

/** The candidates of one pair, as the decision reads them, and their truth. */
struct Pair
{
	std::string site, ref, other;
	bool positive = false, calibration = false;
	std::vector<DecisionCandidate> candidates;
	std::vector<bool> right;
	std::vector<double> error;
};

DecisionCandidate candidateOf(const Row& row, const std::string& where)
{
	DecisionCandidate c;
	for (const auto& f : evidenceFields())
		if (row.count(f.name)) c.evidence.*f.member = number(row, f.name, where);
	c.placement.cells = Similarity2D(number(row, "scale", where), number(row, "yaw_deg", where) * M_PI / 180, {0, 0});
	c.placement.other_centre = {number(row, "centre_x", where), number(row, "centre_y", where)};
	c.screened = number(row, "screened", where) != 0;
	c.mirrored = number(row, "mirrored", where) != 0;
	return c;
}

/** The pairs of a candidates file, in file order (a pair's rows are adjacent). */
std::vector<Pair> loadPairs(const std::string& path)
{
	std::ifstream in(path);
	if (!in) throw std::runtime_error(path + ": cannot be read");
	std::string line;
	if (!std::getline(in, line)) throw std::runtime_error(path + ": empty");
	const std::vector<std::string> columns = splitCsv(line);
	std::vector<Pair> pairs;
	for (size_t n = 2; std::getline(in, line); ++n)
	{
		const std::vector<std::string> cells = splitCsv(line);
		const std::string where = path + ":" + std::to_string(n);
		if (cells.size() != columns.size())
			throw std::runtime_error(where + ": " + std::to_string(cells.size()) + " cells, the header has " +
									 std::to_string(columns.size()));
		Row row;
		for (size_t i = 0; i < cells.size(); ++i) row[columns[i]] = cells[i];
		if (pairs.empty() || pairs.back().site != row["site"] || pairs.back().ref != row["ref"] ||
			pairs.back().other != row["other"])
		{
			Pair p;
			p.site = row["site"], p.ref = row["ref"], p.other = row["other"];
			p.positive = row["positive"] == "1", p.calibration = row["calibration"] == "1";
			pairs.push_back(std::move(p));
		}
		Pair& p = pairs.back();
		p.candidates.push_back(candidateOf(row, where));
		p.right.push_back(row["right"] == "1");
		p.error.push_back(number(row, "error", where));
	}
	return pairs;
}
}  // namespace

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
		for (const Pair& p : loadPairs(csv_arg.getValue()))
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
