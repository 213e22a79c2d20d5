#include <multires_map_merge/ros/MergeMapsService.h>

#include <multires_map_merge/MapIO.h>
#include <multires_map_merge/ros/OccupancyGridConversion.h>

#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace multires_map_merge::ros1
{
namespace
{
/** Runs `body`: whatever it throws becomes an answer (success = false, the
 * reason in the message), never a dead service. */
template <class Response, class Body>
void answerEvenIfItThrows(Response& res, Body body)
{
	try
	{
		body();
	}
	catch (const std::bad_alloc&)
	{
		res.success = false;
		res.message = "not merged: out of memory (maps too large for this machine)";
	}
	catch (const std::exception& e)
	{
		res.success = false;
		res.message = std::string("not merged: ") + e.what();
	}
}

/** maps[i] of a merge_fleet request as grids. Every message that is not a
 * usable grid is named in one error, as gridmap-merge names every bad
 * file: a caller fixing a fleet should not find its bad maps one call at a
 * time. One bad message gives its own error unchanged. */
std::vector<GridInFrame> gridsFromMsgs(const std::vector<nav_msgs::OccupancyGrid>& msgs)
{
	std::vector<GridInFrame> maps;
	std::vector<std::string> problems;
	for (size_t i = 0; i < msgs.size(); ++i)
	{
		try
		{
			maps.push_back(gridFromMsg(msgs[i], "maps[" + std::to_string(i) + "]"));
		}
		catch (const InvalidGridMessage& bad)
		{
			problems.push_back(bad.what());
		}
	}
	if (problems.size() == 1) throw InvalidGridMessage(problems.front());
	if (problems.size() > 1)
	{
		throw InvalidGridMessage(everyMapsProblem(problems, "are not usable grids"));
	}
	return maps;
}

/** A request's output_resolution: 0 (the reference's) or metres > 0. */
double checkedOutputResolution(double requested)
{
	if (std::isfinite(requested) && requested >= 0) return requested;
	std::ostringstream why;
	why << "output_resolution must be 0 (the reference's) or metres > 0, not " << requested;
	throw InvalidGridMessage(why.str());
}
}  // namespace

MergeMapsService::MergeMapsService(const CScalingGridMapAligner::TConfigParams& params) : params_(params)
{
	if (const std::string why = params_.invalidReason(); !why.empty())
		throw std::invalid_argument("invalid aligner parameters: " + why);
}

void MergeMapsService::merge(const MergeMaps::Request& req, MergeMaps::Response& res, Details* details) const
{
	const auto start = std::chrono::steady_clock::now();
	res = MergeMaps::Response();
	res.success = false;
	answerEvenIfItThrows(res, [&]() {
		const double out_res_req = checkedOutputResolution(req.output_resolution);
		const GridInFrame ref = gridFromMsg(req.reference, "reference");
		const GridInFrame other = gridFromMsg(req.other, "other");

		CScalingGridMapAligner aligner;
		aligner.options = params_;
		aligner.options.use_resolution_metadata = params_.use_resolution_metadata || req.use_resolution_metadata;
		const auto info = aligner.alignScaled(ref, other);
		if (details) details->info = info;
		res.overlap = info.overlap;
		res.confidence = info.confidence;
		if (!info.success)
			res.message = "not merged: " + info.message;
		else
		{
			const Similarity2D& world = info.metric;  // between the messages' frames
			res.transform = pose2DOf(world);
			res.scale = world.scale;
			res.scale_cells = info.cells.scale;
			res.implied_resolution_other = info.implied_resolution_other;

			const double out_res = out_res_req > 0 ? out_res_req : ref.grid.getResolution();
			try
			{
				FusedMap fused = fuseGridMaps(ref, other, info.metric, out_res, max_merged_cells);
				res.merged = msgFromGrid(fused.merged, req.reference.header);
				if (details) details->fused = std::move(fused);
				res.success = true;
				res.message = "merged";
			}
			catch (const MergedMapTooLarge& e)
			{
				res.message = std::string("aligned, but the ") + e.what() + " at " + std::to_string(out_res) +
							  " m; ask for a coarser output_resolution";
			}
		}
	});
	if (!res.success) res.merged = nav_msgs::OccupancyGrid();
	res.runtime = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void MergeMapsService::mergeFleet(const MergeFleet::Request& req, MergeFleet::Response& res) const
{
	const auto start = std::chrono::steady_clock::now();
	res = MergeFleet::Response();
	answerEvenIfItThrows(res, [&]() {
		const double out_res_req = checkedOutputResolution(req.output_resolution);
		if (req.maps.size() < 2) throw InvalidGridMessage("maps: give at least two maps");
		if (req.reference >= req.maps.size())
			throw InvalidGridMessage(
				"reference = " + std::to_string(req.reference) + " but there are " + std::to_string(req.maps.size()) + " maps");
		const std::vector<GridInFrame> maps = gridsFromMsgs(req.maps);

		CScalingGridMapAligner aligner;
		aligner.options = params_;
		aligner.options.use_resolution_metadata = params_.use_resolution_metadata || req.use_resolution_metadata;
		const FleetResult r = placeFleet(maps, req.reference, aligner, fleet_params);
		res.pairs_aligned = r.pairs_aligned;
		res.pairs_skipped = r.pairs_skipped;
		size_t placed = 0;
		for (const FleetPlacement& p : r.maps)
		{
			res.placed.push_back(p.placed);
			res.transforms.push_back(pose2DOf(p.in_reference));
			res.scales.push_back(p.placed ? p.in_reference.scale : 0.0);
			res.confidences.push_back(p.confidence);
			res.messages.push_back(p.message);
			placed += p.placed;
		}
		std::ostringstream msg;
		msg << placed << " of " << maps.size() << " maps placed";
		res.message = msg.str();
		if (placed > 1)
		{
			const double out_res = out_res_req > 0 ? out_res_req : maps[req.reference].grid.getResolution();
			try
			{
				const FusedFleet fused = fuseFleet(maps, r, req.reference, out_res, max_merged_cells);
				res.merged = msgFromGrid(fused.merged, req.maps[req.reference].header);
				res.success = r.allPlaced();
			}
			catch (const MergedMapTooLarge& e)
			{
				res.message += std::string(", but the ") + e.what() + " at " + std::to_string(out_res) +
							   " m; ask for a coarser output_resolution";
			}
		}
	});
	res.runtime = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace multires_map_merge::ros1
