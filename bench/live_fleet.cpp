#include "live_fleet.h"

#include <multires_map_merge/FleetMerge.h>
#include <multires_map_merge/ros/LiveFleet.h>
#include <multires_map_merge/ros/OccupancyGridConversion.h>

#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>

namespace multires_bench
{
using namespace multires_map_merge;

namespace
{
struct LiveRobot
{
	std::string name, log;
	double begin, end, res;
	mrpt::poses::CPose2D frame;  //!< its map frame in robot1's (the truth)
	bool other_building;
};

const std::vector<LiveRobot>& liveRobots()
{
	static const std::vector<LiveRobot> r = {
		{"/robot1", "fr079", 0.00, 0.45, 0.05, {}, false},
		{"/robot2", "fr079", 0.30, 0.75, 0.03, {2.0, -1.0, 40 * M_PI / 180}, false},
		{"/robot3", "fr079", 0.55, 0.95, 0.08, {-1.5, 3.0, -120 * M_PI / 180}, false},
		{"/robot4", "intel", 0.00, 0.60, 0.05, {}, true},
	};
	return r;
}

double seconds(std::chrono::steady_clock::time_point since)
{
	return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

/** RMS error of a placement over the robot's occupied cells, in cells of the
 * coarser of its map and robot1's. */
double errorCells(const GridInFrame& map, const LiveRobot& r, const Similarity2D& in_world)
{
	const Similarity2D truth(1, r.frame.phi(), {r.frame.x(), r.frame.y()});
	return pointRmse(in_world, truth, occupiedPointsInMapFrame(map)) / std::max(0.05, r.res);
}
}  // namespace

bool LiveLatency::met() const
{
	if (robots.empty() || max_estimate_s + max_merged_s > period_s) return false;
	for (const auto& r : robots)
	{
		if (r.wrong_steps > 0) return false;
		if (r.other_building) continue;
		if (r.name == robots.front().name) continue;  // the world
		if (r.offline_step >= 0 && (r.live_step < 0 || r.live_step > r.offline_step + 1)) return false;
	}
	return true;
}

LiveLatency runLiveLatency(const ScansOf& scans, int steps)
{
	LiveLatency out;
	out.steps = steps;
	const auto& robots = liveRobots();
	ros1::LiveFleet live(ros1::LiveFleetParams{});
	for (const auto& r : robots)
	{
		live.addRobot(r.name);
		LiveRobotRow row;
		row.name = r.name;
		row.other_building = r.other_building;
		std::ostringstream what;
		what << std::lround(r.res * 100) << " cm, " << std::lround(r.begin * 100) << "–" << std::lround(r.end * 100)
			 << " % of " << r.log << (r.other_building ? " (another building)" : "");
		row.what = what.str();
		out.robots.push_back(row);
	}
	for (int step = 1; step <= steps; ++step)
	{
		std::vector<GridInFrame> maps;
		for (size_t i = 0; i < robots.size(); ++i)
		{
			const auto& r = robots[i];
			const auto& s = scans(r.log);
			const double share = double(step) / steps;
			const size_t b = size_t(r.begin * s.size()), e = size_t((r.begin + share * (r.end - r.begin)) * s.size());
			maps.push_back(renderGridOffLattice(s, b, e, r.res, r.frame, 0.37 * r.res, 0.61 * r.res));
			std_msgs::Header h;
			h.frame_id = r.name + "/map";
			h.stamp = ros::Time(step, 0);
			const std::string why = live.onMap(r.name, ros1::msgFromGrid(maps.back(), h));
			if (!why.empty()) throw std::runtime_error("live bench: " + r.name + ": " + why);
		}
		// When the maps first can be merged: the offline fleet on this step's maps.
		const FleetResult offline = placeFleet(maps, 0, CScalingGridMapAligner());
		for (size_t i = 0; i < robots.size(); ++i)
			if (offline.maps[i].placed && out.robots[i].offline_step < 0 &&
				(robots[i].other_building || errorCells(maps[i], robots[i], offline.maps[i].in_reference) <= 2))
				out.robots[i].offline_step = step;

		auto t0 = std::chrono::steady_clock::now();
		live.estimate();
		out.max_estimate_s = std::max(out.max_estimate_s, seconds(t0));
		t0 = std::chrono::steady_clock::now();
		std::string why;
		live.merged("world", &why);
		out.max_merged_s = std::max(out.max_merged_s, seconds(t0));

		if (live.worldRobot() != robots[0].name)
			throw std::runtime_error("live bench: the world settled on " + live.worldRobot() + ", not " + robots[0].name);
		const auto status = live.status();
		for (size_t i = 0; i < robots.size(); ++i)
		{
			LiveRobotRow& row = out.robots[i];
			if (!status[i].placed)
			{
				row.final_error_cells = -1;
				continue;
			}
			const double e = errorCells(maps[i], robots[i], status[i].in_world);
			const bool right = !robots[i].other_building && e <= 2;
			row.wrong_steps += !right;
			if (right && row.live_step < 0) row.live_step = step;
			row.final_error_cells = e;
		}
		std::cout << "live step " << step << ": estimate " << out.max_estimate_s << " s (slowest so far)" << std::endl;
	}
	return out;
}

void writeLiveSection(std::ostream& md, const LiveLatency& l)
{
	md << "\n## The live node's latency (LiveFleet, as the map_merge node runs it)\n\n"
	   << "Four robots' maps grow over " << l.steps << " steps (at step k each covers k/" << l.steps
	   << " of its share of the run), fed as `nav_msgs/OccupancyGrid` messages in their own frames, with one "
	   << "estimation per step. *Can merge*: the first step at which `placeFleet` on that step's maps places the robot "
	   << "right (within 2 coarse cells); *placed live*: the first step at which the live node has it placed right. "
	   << "The node estimates every " << l.period_s << " s by default (`estimation_rate` 0.5 Hz).\n\n"
	   << "| robot | map | can merge at step | placed live at step | steps placed wrong | final error [coarse cells] |\n"
	   << "|---|---|---|---|---|---|\n";
	auto step = [](int s) { return s < 0 ? std::string("never") : std::to_string(s); };
	for (const auto& r : l.robots)
	{
		std::ostringstream err;
		if (r.final_error_cells < 0) err << "not placed";
		else err << std::fixed << std::setprecision(2) << r.final_error_cells;
		md << "| " << r.name << (&r == &l.robots.front() ? " (world)" : "") << " | " << r.what << " | "
		   << (&r == &l.robots.front() ? "–" : step(r.offline_step)) << " | "
		   << (&r == &l.robots.front() ? "–" : step(r.live_step)) << " | " << r.wrong_steps << " | " << err.str() << " |\n";
	}
	md << "\nSlowest estimation " << std::fixed << std::setprecision(2) << l.max_estimate_s << " s, slowest fusion "
	   << l.max_merged_s << " s, against a period of " << l.period_s << " s.\n";
}

}  // namespace multires_bench
