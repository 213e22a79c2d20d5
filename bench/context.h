#pragma once
// What every experiment of one benchmark run shares, passed explicitly: where
// the data is, this program (experiments that need their own peak memory or a
// time limit run in a child process of it), the aligner's options, and the
// calibration data's writer (candidates.csv) when the run makes it.

#include <multires_map_merge/CScalingGridMapAligner.h>
#include <multires_map_merge/FleetMerge.h>

#include <sys/types.h>

#include <functional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace multires_bench
{
using multires_map_merge::CScalingGridMapAligner;
using multires_map_merge::Similarity2D;
using multires_map_merge::PreparedMap;
using multires_map_merge::FleetParams;

struct BenchContext
{
	std::string data;  //!< ../shared/data
	std::string self;  //!< this program, for child processes
	bool quick = false;  //!< a few pairs per experiment (what CI runs)
	/** The defaults, or --config's; --calibration-data refines every
	 * hypothesis and always searches the structure (no decision cuts the
	 * candidate lists short). */
	CScalingGridMapAligner::TConfigParams options;
	/** The fleet's defaults, or section [fleet] of --config. */
	FleetParams fleet;
	/** --config's file ("" without): children read it too. */
	std::string config;
	/** candidates.csv: every run's candidates (what --calibration-data is for). */
	std::ostream* candidates = nullptr;
	/** --calibration-data: only the candidates matter (no report's extras). */
	bool calibration_only = false;
	/** --pad-to: the Halmstad sensor pairs aligned with each map framed in
	 * this many cells a side of unknown (its map frame unchanged), as
	 * gmapping writes its 4000-cell default grid; 0: the files as they are. */
	int pad_to_cells = 0;

	CScalingGridMapAligner aligner() const;
	/** Reads --config (sections [aligner] and [fleet]); throws naming it. */
	void loadConfig(const std::string& path);
	/** This program with `args`, and --config when given: a child's command. */
	std::vector<std::string> selfWith(std::vector<std::string> args) const;
	/** A fresh folder name under the system's temporary folder, this run's own. */
	std::string tempDir(const std::string& what) const;
};

// ---------------------------------------------------------------- calibration data
/** The columns of candidates.csv: the pair, the truth, the placement, then
 * every evidence field (Decision.h's one list). */
std::string candidateHeader();

/** A candidate's error (pixels or coarse cells) and whether that is right. */
using ErrorOf = std::function<std::pair<double, bool>(const Similarity2D& cells)>;
/** The transform a candidate would be reported with, if decided on. */
using ReportedOf = std::function<Similarity2D(const CScalingGridMapAligner::TCandidate&)>;
/** A candidate (grid cells) as the aligner would report it for maps that
 * bend (finishBent, which works in the prepared maps' cells). */
Similarity2D bentFinished(
	const BenchContext& ctx, const PreparedMap& ref, const PreparedMap& other,
	const CScalingGridMapAligner::TCandidate& c);
/** For negatives: no candidate can be right. */
std::pair<double, bool> noTruth(const Similarity2D&);

/** Every refined hypothesis of the pair, with its evidence and whether it
 * was right (`error_of` judged on `reported_of(candidate)`; the refined
 * cells when not given): what decision-fit fits the
 * decision on. Nothing unless ctx.candidates. */
void writeCandidates(
	const BenchContext& ctx, const std::string& site, const std::string& ref, const std::string& other, bool positive,
	bool calibration, const CScalingGridMapAligner::TReturnInfo& r, const ErrorOf& error_of,
	const ReportedOf& reported_of = {});

// ---------------------------------------------------------------- child processes
/** This process's peak resident memory: VmHWM is this process image's own
 * peak (getrusage would inherit the spawning parent's across exec). */
double peakRssMb();
/** Starts this program again with `args` (args[0] = its path), its standard
 * output into `out_path`. Returns the child's pid, or -1. */
pid_t spawnSelf(std::vector<std::string> args, const std::string& out_path);
/** Runs this program again with `args` (args[0] = its path), its standard
 * output into `out_path`, and waits for it. Throws if it cannot start. */
void runSelf(const std::vector<std::string>& args, const std::string& out_path);

// ---------------------------------------------------------------- report text
std::string num(double v, int prec = 3);
std::string cm(double res);
/** The CPU model and core count. */
std::string machine();

}  // namespace multires_bench
