#pragma once
// Carpin's map-merging test maps (../shared/data/carpin_mapmerge, SOURCES.md
// 4), never used to tune or calibrate anything: maps a user of another
// merger tries first, read as map_server files (carpin_data.h).
// - ap_hill: four partial maps of one run, written roughly co-registered
//   (best offsets within 6 cells, turns of a few degrees): where they lie
//   tells a right place from a wrong one, not how precisely.
// - intel: the Intel lab and Carpin's exact copies of it shifted and turned
//   90°: the truth is exact.
// - UC Merced: two runs of a corridor (LongCorridor1/2) and two of a
//   building with a hall (LongRun6/7), recorded at an unstated cell size:
//   no truth.
// Every place is also judged by cycles: where a ← b, b ← c and a ← c all
// merged, how far a ← c and a ← b ∘ b ← c put c's walls apart.
// Every ordered pair of a place; every map against every map of the other
// places (must not merge).

#include "context.h"

#include <map>
#include <ostream>
#include <string>
#include <vector>

namespace multires_bench
{
struct CarpinPlace
{
	std::string name;
	std::vector<std::string> maps;  //!< file stems under carpin_mapmerge/
	/** Other cell → this place's first map's cell, per map; empty: no truth. */
	std::vector<Similarity2D> truth_to_first;
	/** A right merge lays the other map's occupied cells within this of the
	 * truth (mean) [cells]. */
	double right_within_cells = 0;
};

struct CarpinRun
{
	std::string place, ref, other;  //!< place of REF
	bool positive = false;  //!< same place
	bool has_truth = false;
	bool merged = false, right = false;
	double displacement_cells = NAN;  //!< against the truth, when there is one
	double confidence = 0, seconds = 0;
	Similarity2D metric;  //!< reported, OTHER's frame → REF's
};

struct CarpinCycles
{
	size_t closed = 0;
	double worst_cells = 0;  //!< the largest disagreement [cells of the cycle's first map]
};

struct CarpinResult
{
	std::vector<CarpinRun> runs;
	std::map<std::string, CarpinCycles> cycles;  //!< per place
};

CarpinResult runCarpinMaps(const BenchContext& ctx);

void writeCarpinSection(std::ostream& md, const CarpinResult& result);

/** Merged wrong (against a truth) plus other places' maps merged. */
size_t carpinWrongMerges(const CarpinResult& result);

}  // namespace multires_bench
