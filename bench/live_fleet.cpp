#include "live_fleet.h"

#include <multires_map_merge/FleetMerge.h>
#include <multires_map_merge/ros/LiveFleet.h>
#include <multires_map_merge/ros/OccupancyGridConversion.h>

#include <algorithm>
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
double errorCells(const LiveMap& m, const Similarity2D& in_world)
{
	return pointRmse(in_world, m.frame_in_world, occupiedPointsInMapFrame(m.map)) / std::max(0.05, m.resolution);
}
}  // namespace

std::vector<LiveMap> liveMapsAt(const ScansOf& scans, int state, int states)
{
	std::vector<LiveMap> out;
	for (const auto& r : liveRobots())
	{
		const auto& s = scans(r.log);
		const double share = double(state) / states;
		const size_t b = size_t(r.begin * s.size()), e = size_t((r.begin + share * (r.end - r.begin)) * s.size());
		const GridInFrame rendered = renderGridOffLattice(s, b, e, r.res, r.frame, 0.37 * r.res, 0.61 * r.res);
		std_msgs::Header h;
		h.frame_id = r.name + "/map";
		h.stamp = ros::Time(state, 0);
		LiveMap m;
		m.robot = r.name;
		m.msg = ros1::msgFromGrid(rendered, h);
		m.map = ros1::gridFromMsg(m.msg, r.name + "'s map");
		m.frame_in_world = Similarity2D(1, r.frame.phi(), {r.frame.x(), r.frame.y()});
		m.resolution = r.res;
		m.other_building = r.other_building;
		out.push_back(std::move(m));
	}
	return out;
}

double LiveLatency::maxEstimateSeconds() const
{
	double m = 0;
	for (const auto& e : estimations) m = std::max(m, e.estimate_s + e.merged_s);
	return m;
}

double LiveLatency::medianEstimateSeconds() const
{
	std::vector<double> d;
	for (const auto& e : estimations) d.push_back(e.estimate_s + e.merged_s);
	if (d.empty()) return 0;
	std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
	return d[d.size() / 2];
}

double LiveLatency::maxLatencySeconds() const
{
	double m = 0;
	for (const auto& r : robots)
	{
		if (r.other_building || &r == &robots.front() || r.can_merge_s < 0) continue;
		if (r.placed_s < 0) return -1;
		m = std::max(m, r.latencySeconds());
	}
	return m;
}

bool LiveLatency::met() const
{
	if (robots.empty() || estimations.empty()) return false;
	for (const auto& r : robots)
	{
		if (r.wrong_estimations > 0) return false;
		if (r.other_building || &r == &robots.front()) continue;
		if (r.can_merge_s >= 0 && (r.placed_s < 0 || r.latencySeconds() > 2 * period_s)) return false;
	}
	return true;
}

LiveLatency runLiveLatency(
	const ScansOf& scans, int states, const CScalingGridMapAligner::TConfigParams& aligner, const FleetParams& fleet)
{
	LiveLatency out;
	out.states = states;
	const auto& robots = liveRobots();
	ros1::LiveFleetParams params;  // as the node sets them at its default rate
	params.aligner = aligner;
	params.placement = fleet;
	params.estimation_budget_s = ros1::defaultEstimationBudget(1.0 / out.period_s);
	out.budget_s = params.estimation_budget_s;
	ros1::LiveFleet live(params);
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
	// Every map state, and when the maps first can be merged (offline).
	std::vector<std::vector<LiveMap>> maps_at(states + 1);
	for (int k = 1; k <= states; ++k)
	{
		maps_at[k] = liveMapsAt(scans, k, states);
		std::vector<GridInFrame> grids;
		for (const auto& m : maps_at[k]) grids.push_back(m.map);
		const bool all_known = std::all_of(out.robots.begin() + 1, out.robots.end(), [](const LiveRobotRow& r) {
			return r.other_building || r.can_merge_state >= 0;
		});
		if (all_known) continue;
		const FleetResult offline = placeFleet(grids, 0, CScalingGridMapAligner());
		for (size_t i = 1; i < robots.size(); ++i)
			if (offline.maps[i].placed && out.robots[i].can_merge_state < 0 && !robots[i].other_building &&
				errorCells(maps_at[k][i], offline.maps[i].in_reference) <= 2)
				out.robots[i].can_merge_state = k, out.robots[i].can_merge_s = (k - 1) * out.state_s;
	}

	// The node: an estimation every period, or right after the previous one
	// when that took longer; it sees the maps that arrived before it started.
	int fed = 0;
	const double last_state_s = (states - 1) * out.state_s;
	for (double start = 0, tick = 0;;)
	{
		const int state = std::min(states, 1 + int(std::floor(start / out.state_s + 1e-9)));
		if (state != fed)
		{
			for (size_t i = 0; i < robots.size(); ++i)
			{
				const std::string why = live.onMap(robots[i].name, maps_at[state][i].msg);
				if (!why.empty()) throw std::runtime_error("live bench: " + robots[i].name + ": " + why);
			}
			fed = state;
		}
		LiveEstimationRow row;
		row.start_s = start, row.state = state;
		auto t0 = std::chrono::steady_clock::now();
		live.estimate();
		row.estimate_s = seconds(t0);
		t0 = std::chrono::steady_clock::now();
		std::string why;
		live.merged("world", &why);
		row.merged_s = seconds(t0);
		const auto st = live.lastEstimation();
		row.maps_prepared = st.maps_prepared, row.pairs_aligned = st.pairs_aligned;
		row.pairs_reused = st.pairs_reused, row.pairs_deferred = st.pairs_deferred;
		out.estimations.push_back(row);
		// The node fuses and publishes on its own timer (merging_rate, 4 Hz):
		// the placement shows at the next tick after the estimation, plus the
		// fusion; the next estimation does not wait for it.
		const double published = start + row.estimate_s + 1.0 / 4.0 + row.merged_s;

		if (live.worldRobot() != robots[0].name)
			throw std::runtime_error("live bench: the world settled on " + live.worldRobot() + ", not " + robots[0].name);
		const auto status = live.status();
		for (size_t i = 0; i < robots.size(); ++i)
		{
			LiveRobotRow& r = out.robots[i];
			if (!status[i].placed)
			{
				r.final_error_cells = -1;
				continue;
			}
			const double e = errorCells(maps_at[state][i], status[i].in_world);
			const bool right = !robots[i].other_building && e <= 2;
			r.wrong_estimations += !right;
			if (!right)
				std::cout << "live t=" << start << " s: " << robots[i].name << " placed wrong, " << e << " coarse cells off"
						  << std::endl;
			if (right && r.placed_s < 0) r.placed_s = published;
			r.final_error_cells = e;
		}
		std::cout << "live t=" << start << " s, maps of state " << state << ": estimate " << row.estimate_s
				  << " s, maps prepared " << st.maps_prepared << "/" << st.maps << ", pairs aligned " << st.pairs_aligned
				  << ", reused " << st.pairs_reused << ", deferred " << st.pairs_deferred << std::endl;
		// Run until the last maps have had two periods.
		if (start >= last_state_s + 2 * out.period_s) break;
		while (tick <= start) tick += out.period_s;
		start = std::max(tick, start + row.estimate_s);
	}
	return out;
}

void writeLiveSection(std::ostream& md, const LiveLatency& l)
{
	md << "\n## The live node's latency (LiveFleet, as the map_merge node runs it)\n\n"
	   << "Four robots' maps grow in " << l.states << " states, one every " << l.state_s
	   << " s of simulated time (state k covers k/" << l.states
	   << " of each robot's share of the run: the robots explore faster than real ones, so the maps change more "
	   << "between estimations), fed as `nav_msgs/OccupancyGrid` messages in their own frames. The node estimates "
	   << "every " << l.period_s << " s (`estimation_rate` 0.5 Hz, its default), or right after the previous "
	   << "estimation if that took longer, with the estimation budget it sets by default (" << l.budget_s
	   << " s: no pair starts later); each estimation takes the time it measures on this machine. *Can merge*: "
	   << "when the first state arrived on which `placeFleet` places the robot right (within 2 coarse cells); "
	   << "*published*: when the node's first estimation that has it placed right ends, plus the node's merging "
	   << "period (0.25 s) and the fusion.\n\n"
	   << "| robot | map | can merge at [s] | published at [s] | latency [s] | estimations placed wrong | final error [coarse cells] |\n"
	   << "|---|---|---|---|---|---|---|\n";
	auto time = [](double s) {
		std::ostringstream o;
		if (s < 0) o << "never";
		else o << std::fixed << std::setprecision(1) << s;
		return o.str();
	};
	for (const auto& r : l.robots)
	{
		const bool world = &r == &l.robots.front();
		std::ostringstream err;
		if (r.final_error_cells < 0) err << "not placed";
		else err << std::fixed << std::setprecision(2) << r.final_error_cells;
		md << "| " << r.name << (world ? " (world)" : "") << " | " << r.what << " | "
		   << (world ? "–" : time(r.can_merge_s)) << " | " << (world ? "–" : time(r.placed_s)) << " | "
		   << (world || r.latencySeconds() < 0 ? std::string("–") : time(r.latencySeconds())) << " | "
		   << r.wrong_estimations << " | " << err.str() << " |\n";
	}
	size_t aligned = 0, reused = 0, deferred = 0, prepared = 0;
	for (const auto& e : l.estimations)
		aligned += e.pairs_aligned, reused += e.pairs_reused, deferred += e.pairs_deferred, prepared += e.maps_prepared;
	md << "\n" << l.estimations.size() << " estimations; each (with its fusion) took median " << std::fixed
	   << std::setprecision(2) << l.medianEstimateSeconds() << " s, max " << l.maxEstimateSeconds()
	   << " s, against a period of " << l.period_s << " s. Over all of them: " << prepared << " maps prepared, "
	   << aligned << " pairs aligned, " << reused << " earlier results reused (maps unchanged, or a refused pair whose "
	   << "maps grew less than `retry_growth`), " << deferred << " pairs deferred past the budget.\n";
}

}  // namespace multires_bench
