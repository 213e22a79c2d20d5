#include "mrpt_anchor.h"

#include <multires_map_merge/GridImage.h>

#include <mrpt/maps/CMultiMetricMap.h>
#include <mrpt/maps/CSimplePointsMap.h>
#include <mrpt/poses/CPosePDFSOG.h>
#include <mrpt/slam/CGridMapAligner.h>
#include <mrpt/system/CTicTac.h>

#include <sstream>

namespace multires_bench
{
namespace
{
mrpt::maps::CMultiMetricMap withPoints(const mrpt::maps::COccupancyGridMap2D& grid)
{
	mrpt::maps::CMultiMetricMap mm;
	auto g = mrpt::maps::COccupancyGridMap2D::Create();
	*g = grid;
	auto pts = mrpt::maps::CSimplePointsMap::Create();
	for (unsigned cy = 0; cy < grid.getSizeY(); ++cy)
		for (unsigned cx = 0; cx < grid.getSizeX(); ++cx)
			if (multires_map_merge::occupancyProbability(grid, cx, cy) > multires_map_merge::kOccupiedAbove)
				pts->insertPoint(grid.idx2x(cx), grid.idx2y(cy), 0);
	mm.maps.push_back(g);
	mm.maps.push_back(pts);
	return mm;
}
}  // namespace

AnchorResult alignWithMrpt(
	const mrpt::maps::COccupancyGridMap2D& ref, const mrpt::maps::COccupancyGridMap2D& other)
{
	AnchorResult out;
	mrpt::system::CTicTac clock;
	try
	{
		const auto m1 = withPoints(ref), m2 = withPoints(other);
		mrpt::slam::CGridMapAligner aligner;
		aligner.setMinLoggingLevel(mrpt::system::LVL_ERROR);
		aligner.options.featsPerSquareMeter = 0.1f;
		mrpt::slam::CGridMapAligner::TReturnInfo info;
		clock.Tic();
		const auto pdf = aligner.Align(&m1, &m2, mrpt::poses::CPose2D(), info);
		out.seconds = clock.Tac();
		const auto sog = std::dynamic_pointer_cast<mrpt::poses::CPosePDFSOG>(pdf);
		if (!pdf || (sog && sog->size() == 0))
		{
			out.why = "no pose (no consistent feature matches)";
			return out;
		}
		// The most likely mode, as MRPT's grid-matching application reports it.
		mrpt::poses::CPose2D pose;
		if (sog)
		{
			bool first = true;
			double best = 0;
			for (const auto& mode : *sog)
				if (first || mode.log_w > best)
				{
					first = false;
					best = mode.log_w;
					pose = mode.mean;
				}
		}
		else
			pose = pdf->getMeanVal();
		out.aligned = true;
		out.metric = multires_map_merge::Similarity2D(1, pose.phi(), {pose.x(), pose.y()});
	}
	catch (const std::exception& e)
	{
		out.seconds = clock.Tac();
		// MRPT's messages open with a banner; keep the line that says what failed.
		std::istringstream lines(e.what());
		std::string line;
		while (std::getline(lines, line))
			if (!line.empty() && line.rfind("====", 0) != 0)
			{
				out.why = line.substr(line.rfind(": [") == std::string::npos ? 0 : line.rfind(": [") + 2);
				break;
			}
		if (out.why.empty()) out.why = "MRPT exception";
	}
	return out;
}

}  // namespace multires_bench
