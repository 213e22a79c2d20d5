#include <multires_map_merge/GridMapFusion.h>
#include <multires_map_merge/ros/LiveFleet.h>
#include <multires_map_merge/ros/OccupancyGridConversion.h>

#include <algorithm>
#include <chrono>
#include <functional>
#include <numeric>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace multires_map_merge::ros1
{
namespace
{
size_t knownCells(const nav_msgs::OccupancyGrid& msg)
{
	return size_t(std::count_if(msg.data.begin(), msg.data.end(), [](int8_t v) { return v >= 0; }));
}
}  // namespace

LiveFleet::LiveFleet(const LiveFleetParams& params) : params_(params)
{
	if (const std::string why = params_.aligner.invalidReason(); !why.empty())
		throw std::invalid_argument("invalid aligner parameters: " + why);
	if (const std::string why = params_.placement.invalidReason(); !why.empty())
		throw std::invalid_argument("invalid fleet parameters: " + why);
	if (!(params_.output_resolution >= 0) || !std::isfinite(params_.output_resolution))
		throw std::invalid_argument("output_resolution must be 0 (the world robot's) or metres > 0");
	if (!(params_.agreement_cells > 0)) throw std::invalid_argument("agreement_cells must be > 0");
	if (!(params_.retry_growth >= 0) || !std::isfinite(params_.retry_growth))
		throw std::invalid_argument("retry_growth must be a share >= 0");
	if (!(params_.estimation_budget_s >= 0) || !std::isfinite(params_.estimation_budget_s))
		throw std::invalid_argument("estimation_budget_s must be seconds >= 0 (0: no limit)");
}

LiveFleet::Robot* LiveFleet::find(const std::string& name)
{
	for (auto& r : robots_)
		if (r.name == name) return &r;
	return nullptr;
}

const LiveFleet::Robot* LiveFleet::find(const std::string& name) const
{
	return const_cast<LiveFleet*>(this)->find(name);
}

void LiveFleet::addRobot(const std::string& name, const std::optional<Similarity2D>& init_pose)
{
	std::lock_guard<std::mutex> lock(mutex_);
	if (find(name)) return;
	Robot r;
	r.name = name;
	r.init_pose = init_pose;
	r.message = "no map yet";
	robots_.push_back(std::move(r));
}

bool LiveFleet::hasRobot(const std::string& name) const
{
	std::lock_guard<std::mutex> lock(mutex_);
	return find(name) != nullptr;
}

std::string LiveFleet::onMap(const std::string& robot, const nav_msgs::OccupancyGrid& msg)
{
	std::shared_ptr<const GridInFrame> grid;
	try
	{
		grid = std::make_shared<const GridInFrame>(gridFromMsg(msg, robot + "'s map"));  // a bad map never replaces a good one
	}
	catch (const std::exception& e)
	{
		return std::string("ignored: ") + e.what();
	}
	std::lock_guard<std::mutex> lock(mutex_);
	Robot* r = find(robot);
	if (!r) return "ignored: unknown robot '" + robot + "'";
	if (r->map && r->map->header.stamp > msg.header.stamp)
		return "ignored: older than the map held for " + robot;
	// A map sent again unchanged (SLAM nodes republish) changes nothing to
	// estimate or fuse.
	const bool same = r->map && r->map->info == msg.info && r->map->data == msg.data &&
		r->map->header.frame_id == msg.header.frame_id;
	r->map = msg;
	if (same) return "";
	++r->map_version;
	r->grid = std::move(grid), r->converted_version = r->map_version;
	r->known_cells = knownCells(msg);
	++version_;
	if (world_robot_.empty() && !params_.known_init_poses) world_robot_ = robot;
	return "";
}

std::string LiveFleet::onUpdate(const std::string& robot, const map_msgs::OccupancyGridUpdate& msg)
{
	std::lock_guard<std::mutex> lock(mutex_);
	Robot* r = find(robot);
	if (!r) return "ignored update: unknown robot '" + robot + "'";
	if (!r->map) return "ignored update for " + robot + ": no full map to update yet";
	std::ostringstream why;
	if (uint64_t(msg.width) * msg.height != msg.data.size())
		why << "data has " << msg.data.size() << " cells, not width x height = " << msg.width << " x " << msg.height;
	else if (msg.x < 0 || msg.y < 0)
		why << "negative x, y (" << msg.x << ", " << msg.y << ")";
	else if (std::any_of(msg.data.begin(), msg.data.end(), [](int8_t v) { return v < -1 || v > 100; }))
		why << "a cell value outside -1..100";
	nav_msgs::OccupancyGrid& map = *r->map;
	if (why.tellp() == 0 && (uint64_t(msg.x) >= map.info.width || uint64_t(msg.y) >= map.info.height))
		why << "region at (" << msg.x << ", " << msg.y << ") lies outside the " << map.info.width << " x "
			<< map.info.height << " map";
	if (why.tellp() > 0) return "ignored update for " + robot + ": " + why.str();
	// What fits is applied (as map_server's consumers do); the rest is cut.
	const uint32_t w = std::min<uint32_t>(msg.width, map.info.width - msg.x);
	const uint32_t h = std::min<uint32_t>(msg.height, map.info.height - msg.y);
	for (uint32_t y = 0; y < h; ++y)
		std::copy_n(msg.data.begin() + size_t(y) * msg.width, w,
					map.data.begin() + size_t(msg.y + y) * map.info.width + msg.x);
	if (msg.header.stamp > map.header.stamp) map.header.stamp = msg.header.stamp;
	++r->map_version;
	++version_;
	return "";
}

const GridInFrame& LiveFleet::converted(Robot& r)
{
	if (r.converted_version != r.map_version)
	{
		r.grid = std::make_shared<const GridInFrame>(gridFromMsg(*r.map, r.name));  // validated on arrival
		r.known_cells = knownCells(*r.map);
		r.converted_version = r.map_version;
	}
	return *r.grid;
}

bool LiveFleet::agree(const GridInFrame& map, const Similarity2D& a, const Similarity2D& b) const
{
	return cornerRms(map, a, b) <= params_.agreement_cells * map.grid.getResolution() * std::max(a.scale, b.scale);
}

bool LiveFleet::worldCommitted() const
{
	std::lock_guard<std::mutex> lock(mutex_);
	return std::any_of(robots_.begin(), robots_.end(), [&](const Robot& r) { return r.placed && r.name != world_robot_; });
}

namespace
{
/** A member (the first in input order) of the largest group of maps that
 * confident pairs connect, if that group has two maps or more; else -1. */
int largestGroupMember(size_t n, const std::vector<FleetEdge>& edges)
{
	std::vector<size_t> parent(n);
	std::iota(parent.begin(), parent.end(), 0);
	std::function<size_t(size_t)> root = [&](size_t a) { return parent[a] == a ? a : parent[a] = root(parent[a]); };
	for (const auto& e : edges)
		if (e.merged && !e.dropped) parent[root(e.from)] = root(e.to);
	std::vector<size_t> size(n, 0);
	for (size_t i = 0; i < n; ++i) ++size[root(i)];
	int best = -1;
	for (size_t i = 0; i < n; ++i)
		if (size[root(i)] >= 2 && (best < 0 || size[root(i)] > size[root(size_t(best))])) best = int(i);
	return best;
}
}  // namespace

void LiveFleet::placeAtKnownPoses()
{
	++version_;
	for (auto& r : robots_)
	{
		r.placed = r.map && r.init_pose;
		if (r.placed) r.in_world = *r.init_pose, r.confidence = 1, r.message = "placed at its known initial pose";
		else if (r.map) r.message = "no initial pose (map_merge/init_pose_x, _y, _z, _yaw in its namespace)";
	}
}

std::optional<LiveFleet::Snapshot> LiveFleet::takeSnapshot()
{
	if (world_robot_.empty()) return std::nullopt;
	Snapshot s;
	s.estimation = estimations_;
	for (size_t i = 0; i < robots_.size(); ++i)
		if (Robot& r = robots_[i]; r.map)
		{
			if (r.name == world_robot_) s.world = s.names.size();
			s.names.push_back(r.name);
			s.maps.push_back(converted(r));
			s.robot_of.push_back(i);
			s.versions.push_back(r.map_version);
			s.pending.push_back(r.pending.has_value());
			s.known_cells.push_back(r.known_cells);
		}
	return s;
}

FleetHints LiveFleet::hintsFor(const Snapshot& s, std::chrono::steady_clock::time_point started)
{
	FleetHints hints;
	for (size_t m = 0; m < s.maps.size(); ++m)
	{
		const auto it = prepared_memory_.find(s.robot_of[m]);
		const bool current = it != prepared_memory_.end() && it->second.map_version == s.versions[m];
		hints.prepared.push_back(current ? it->second.prepared : nullptr);
		if (!current && it != prepared_memory_.end()) prepared_memory_.erase(it);  // not two of a map at once
	}
	hints.known = [this, &s](size_t a, size_t b) -> std::optional<FleetHints::Known> {
		const auto it = pair_memory_.find(std::minmax(s.robot_of[a], s.robot_of[b]));
		if (it == pair_memory_.end()) return std::nullopt;
		const PairMemory& mem = it->second;
		auto index_of = [&](size_t robot) {
			return size_t(std::find(s.robot_of.begin(), s.robot_of.end(), robot) - s.robot_of.begin());
		};
		FleetHints::Known k;
		k.edge = mem.edge;
		k.edge.to = index_of(mem.edge.to), k.edge.from = index_of(mem.edge.from);
		const size_t to = k.edge.to, from = k.edge.from;
		const bool unchanged = s.versions[to] == mem.to_version && s.versions[from] == mem.from_version;
		auto grew = [&](size_t now, size_t then) { return double(now) > (1 + params_.retry_growth) * double(then); };
		const bool worth_retrying = grew(s.known_cells[to], mem.to_known) || grew(s.known_cells[from], mem.from_known) ||
			s.estimation >= mem.estimation + params_.retry_estimations;
		k.holds = unchanged || (!mem.edge.merged && !worth_retrying);
		k.age = s.estimation - mem.estimation;
		// Tracking follows the last result; a fresh search now and then, and
		// whenever a move awaits confirmation, keeps a wrong placement from
		// confirming itself.
		k.track = !s.pending[to] && !s.pending[from] && mem.searched &&
			s.estimation < *mem.searched + params_.retry_estimations;
		return k;
	};
	hints.overdue_age = params_.retry_estimations;
	if (params_.estimation_budget_s > 0)
		hints.deadline = started + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
									   std::chrono::duration<double>(params_.estimation_budget_s));
	return hints;
}

void LiveFleet::remember(const Snapshot& s, const FleetResult& result)
{
	for (size_t m = 0; m < s.maps.size(); ++m)
		if (result.prepared[m]->problem.rfind("could not be prepared", 0) != 0)  // a failure is tried again
			prepared_memory_[s.robot_of[m]] = {s.versions[m], result.prepared[m]};
	// Every fresh alignment, as the aligner gave it: one dropped around a
	// cycle is dropped again while its maps stay as they are.
	for (const FleetEdge& e : result.edges)
	{
		if (e.reused) continue;
		const auto key = std::minmax(s.robot_of[e.to], s.robot_of[e.from]);
		PairMemory mem;
		mem.edge = e;
		mem.edge.dropped = false;
		mem.edge.to = s.robot_of[e.to], mem.edge.from = s.robot_of[e.from];
		mem.to_version = s.versions[e.to], mem.from_version = s.versions[e.from];
		mem.to_known = s.known_cells[e.to], mem.from_known = s.known_cells[e.from];
		mem.estimation = s.estimation;
		const auto before = pair_memory_.find(key);
		// Tracked (from its earlier result, or from where the fleet put its
		// maps) is not searched afresh: it keeps when it last was, if ever.
		if (!e.tracked) mem.searched = s.estimation;
		else if (before != pair_memory_.end()) mem.searched = before->second.searched;
		pair_memory_[key] = mem;
	}
}

bool LiveFleet::moveWorldIfAlone(const Snapshot& s, size_t& world, FleetResult& result) const
{
	const bool alone = std::none_of(result.maps.begin(), result.maps.end(), [&](const FleetPlacement& p) {
		return p.placed && &p != &result.maps[world];
	});
	if (!alone || worldCommitted()) return false;
	const int better = largestGroupMember(s.maps.size(), result.edges);
	if (better < 0 || size_t(better) == world) return false;
	world = size_t(better);
	// On the pairs aligned so far, placed as placeFleet places them.
	result = placeFromPairs(s.maps, world, result.edges, params_.placement.resolvedFor(params_.aligner.decision));
	return true;
}

void LiveFleet::estimate()
{
	// Snapshot under the lock; align without it (maps keep arriving).
	const auto started = std::chrono::steady_clock::now();
	std::optional<Snapshot> snapshot;
	{
		std::lock_guard<std::mutex> lock(mutex_);
		++estimations_;
		if (params_.known_init_poses) return placeAtKnownPoses();
		if (!(snapshot = takeSnapshot())) return;
	}
	const Snapshot& s = *snapshot;
	size_t world = s.world;
	std::optional<FleetResult> result;
	std::string failure;
	bool world_moved = false;
	EstimationStats stats;
	stats.maps = s.maps.size();
	if (s.maps.size() >= 2)
	{
		try
		{
			const FleetHints hints = hintsFor(s, started);
			CScalingGridMapAligner aligner;
			aligner.options = params_.aligner;
			result = placeFleet(s.maps, world, aligner, params_.placement, hints);
			stats.pairs_aligned = result->pairs_aligned, stats.pairs_reused = result->pairs_reused;
			stats.pairs_deferred = result->pairs_deferred, stats.pairs_skipped = result->pairs_skipped;
			stats.maps_prepared = size_t(std::count(hints.prepared.begin(), hints.prepared.end(), nullptr));
			remember(s, *result);
			world_moved = moveWorldIfAlone(s, world, *result);
		}
		catch (const std::exception& e)
		{
			failure = e.what();
		}
	}
	stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
	std::lock_guard<std::mutex> lock(mutex_);
	last_estimation_ = stats;
	++version_;  // placements may have changed
	if (world_moved)
	{
		world_robot_ = s.names[world];
		for (auto& r : robots_) r.placed = false, r.pending.reset();  // nobody else was placed yet
	}
	applyEstimate(s, world, result, failure);
}

void LiveFleet::applyEstimate(
	const Snapshot& s, size_t world, const std::optional<FleetResult>& result, const std::string& failure)
{
	for (size_t i = 0; i < s.names.size(); ++i)
	{
		Robot& r = *find(s.names[i]);
		if (i == world)
		{
			r.placed = true, r.in_world = Similarity2D(), r.confidence = 1, r.message = "the world frame is its map frame";
			continue;
		}
		if (!result)
		{
			if (!failure.empty()) r.message = (r.placed ? "kept its placement; estimation failed: " : "estimation failed: ") + failure;
			continue;
		}
		const FleetPlacement& p = result->maps[i];
		if (!p.placed)
		{
			r.message = r.placed ? "kept its last placement; latest estimate: " + p.message : p.message;
			continue;
		}
		const std::string through = p.parent >= 0 && size_t(p.parent) != world ? " through " + s.names[p.parent] : "";
		if (!r.placed || agree(s.maps[i], r.in_world, p.in_reference))
		{
			r.message = (r.placed ? "placement refined" : "placed") + through;
			r.placed = true, r.in_world = p.in_reference, r.confidence = p.confidence, r.pending.reset();
		}
		else if (r.pending && agree(s.maps[i], *r.pending, p.in_reference))
		{
			r.message = "moved to a new placement confirmed twice" + through;
			r.in_world = p.in_reference, r.confidence = p.confidence, r.pending.reset();
		}
		else
		{
			r.pending = p.in_reference;
			r.message = "kept its placement; a different one awaits confirmation" + through;
		}
	}
}

std::optional<nav_msgs::OccupancyGrid> LiveFleet::merged(const std::string& world_frame, std::string* why)
{
	std::vector<GridInFrame> maps;
	FleetResult placement;
	std_msgs::Header header;
	size_t ref = 0;  // the world robot, else (known poses) the first placed: a rigid placement
	size_t version = 0;
	{
		std::lock_guard<std::mutex> lock(mutex_);
		if (merged_version_ == version_ && merged_frame_ == world_frame)
		{
			if (why) *why = merged_why_;
			return merged_cache_;
		}
		version = version_;
		for (auto& r : robots_)
			if (r.map && r.placed)
			{
				if (r.name == world_robot_) ref = maps.size();
				maps.push_back(converted(r));
				FleetPlacement p;
				p.placed = true, p.in_reference = r.in_world, p.confidence = r.confidence;
				placement.maps.push_back(p);
				if (r.map->header.stamp > header.stamp) header.stamp = r.map->header.stamp;
			}
	}
	std::optional<nav_msgs::OccupancyGrid> result;
	std::string failure;
	if (maps.empty())
		failure = "no robot placed yet";
	else
	{
		try
		{
			// Fused in the reference robot's map frame, then put in the world:
			// the world is that frame, or (known poses) where they are given.
			const Similarity2D to_world = placement.maps[ref].in_reference;
			for (auto& p : placement.maps) p.in_reference = to_world.inverse().compose(p.in_reference);
			const double res = params_.output_resolution > 0 ? params_.output_resolution : maps[ref].grid.getResolution();
			FusedFleet fused = fuseFleet(maps, placement, ref, res, params_.max_merged_cells);
			fused.merged.origin = to_world.compose(fused.merged.origin);
			header.frame_id = world_frame;
			result = msgFromGrid(fused.merged, header);
		}
		catch (const std::exception& e)
		{
			failure = e.what();
		}
	}
	if (why) *why = failure;
	std::lock_guard<std::mutex> lock(mutex_);
	if (version_ == version)  // nothing changed meanwhile: keep it for the next call
		merged_version_ = version, merged_cache_ = result, merged_why_ = failure, merged_frame_ = world_frame;
	return result;
}

double LiveFleet::scalePrecision(const Robot& r) const
{
	// A placement is good to about a coarse cell at each end of the map: its
	// scale to about two coarse cells over the map's extent.
	const auto& info = r.map->info;
	const double extent = info.resolution * std::hypot(double(info.width), double(info.height));
	double world_cell = info.resolution;
	for (const auto& w : robots_)
		if (w.name == world_robot_ && w.map) world_cell = w.map->info.resolution;
	const double coarse = std::max<double>(info.resolution, world_cell / r.in_world.scale);
	return extent > 0 ? 2 * coarse / extent : 0.0;
}

std::vector<LiveFleet::RobotStatus> LiveFleet::status() const
{
	std::lock_guard<std::mutex> lock(mutex_);
	std::vector<RobotStatus> out;
	for (const auto& r : robots_)
	{
		RobotStatus s;
		s.name = r.name;
		s.frame_id = r.map && !r.map->header.frame_id.empty() ? r.map->header.frame_id : r.name + "/map";
		s.has_map = r.map.has_value();
		s.placed = r.placed;
		s.in_world = r.in_world;
		s.confidence = r.confidence;
		s.message = r.message;
		s.stated_resolution_off = r.placed && r.map && std::abs(std::log(r.in_world.scale)) > scalePrecision(r);
		out.push_back(s);
	}
	return out;
}

std::string LiveFleet::worldRobot() const
{
	std::lock_guard<std::mutex> lock(mutex_);
	return world_robot_;
}

size_t LiveFleet::estimations() const
{
	std::lock_guard<std::mutex> lock(mutex_);
	return estimations_;
}

LiveFleet::EstimationStats LiveFleet::lastEstimation() const
{
	std::lock_guard<std::mutex> lock(mutex_);
	return last_estimation_;
}

}  // namespace multires_map_merge::ros1
