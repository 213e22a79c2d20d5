#include "CandidatesCsv.h"

#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <tuple>

namespace multires_map_merge
{
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

DecisionCandidate candidateOf(const Row& row, const std::string& where)
{
	DecisionCandidate c;
	for (const auto& f : evidenceFields())
		// A column older samples lack reads as 0 (_fit1.csv etc. have no
		// exact_confidence: measured before it existed, as 0 would say).
		if (row.count(f.name)) c.evidence.*f.member = number(row, f.name, where);
	c.placement.cells = Similarity2D(number(row, "scale", where), number(row, "yaw_deg", where) * M_PI / 180, {0, 0});
	c.placement.other_centre = {number(row, "centre_x", where), number(row, "centre_y", where)};
	c.screened = number(row, "screened", where) != 0;
	c.mirrored = number(row, "mirrored", where) != 0;
	return c;
}
}  // namespace

std::vector<CandidatePair> loadCandidatePairs(const std::string& path)
{
	std::ifstream in(path);
	if (!in) throw std::runtime_error(path + ": cannot be read");
	std::string line;
	if (!std::getline(in, line)) throw std::runtime_error(path + ": empty");
	const std::vector<std::string> columns = splitCsv(line);
	std::vector<CandidatePair> pairs;
	std::set<std::tuple<std::string, std::string, std::string>> seen;
	bool repeated = false;  // the rows of a pair read before
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
			repeated = !seen.emplace(row["site"], row["ref"], row["other"]).second;
			if (repeated) continue;
			CandidatePair p;
			p.site = row["site"], p.ref = row["ref"], p.other = row["other"];
			p.positive = row["positive"] == "1", p.calibration = row["calibration"] == "1";
			pairs.push_back(std::move(p));
		}
		if (repeated) continue;
		CandidatePair& p = pairs.back();
		p.candidates.push_back(candidateOf(row, where));
		p.right.push_back(row["right"] == "1");
		p.error.push_back(number(row, "error", where));
	}
	return pairs;
}

}  // namespace multires_map_merge
