#pragma once
// Cost: the fr079 pair at growing map sizes, and whole processes against
// MRPT's, each in a fresh child process of this program (its own peak memory,
// a time limit for MRPT). The child modes are what those processes run.

#include "context.h"

#include <string>

namespace multires_bench
{
/** The fr079 pair with the reference's longer side about `cells` cells (the
 * other at half the resolution, turned 30°), padded square, aligned in a
 * fresh process. */
struct ScalingCase
{
	int cells = 0;  //!< longer side of the reference map
	double ref_res = 0, other_res = 0, seconds = 0, peak_mb = 0;
	double process_seconds = 0;  //!< the whole child process: start, loading both files, aligning, exit
	unsigned ref_w = 0, ref_h = 0;
	bool merged = false;
	std::string message;  //!< the aligner's
};
ScalingCase runScalingCase(const BenchContext& ctx, int cells);

/** One same-resolution fr079 pair as whole processes: ours and MRPT's, each
 * loading the two map_server files, aligning and exiting (median of 3). */
struct WholeProcessRow
{
	double res = 0, ours_s = 0, mrpt_s = 0, ours_peak_mb = 0, mrpt_peak_mb = 0;
	bool ours_merged = false, mrpt_aligned = false;
};
WholeProcessRow runWholeProcess(const BenchContext& ctx, double res);

/** MRPT's aligner on two map files in a child process, killed after `limit_s`. */
struct LimitedMrpt
{
	bool finished = false, aligned = false;
	double seconds = 0;
	Similarity2D metric;
};
LimitedMrpt mrptWithTimeLimit(const std::string& self, const std::string& ref, const std::string& other, double limit_s);

// Child modes (this program run with --scaling-align / --mrpt-align).
/** Aligns two saved grids and prints the time, result and peak memory. */
int scalingChild(const BenchContext& ctx, const std::string& ref_path, const std::string& other_path);
/** MRPT's aligner on two map files; prints the pose between the maps' frames. */
int mrptChild(const std::string& ref_path, const std::string& other_path);

}  // namespace multires_bench
