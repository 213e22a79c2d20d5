#pragma once
// Real map pairs as nav_msgs/OccupancyGrid messages, placed in their frames
// by chosen origin poses, with the exact transform between the two frames;
// and the checks every ROS-side test makes of a merge_maps response.

#include <multires_map_merge/EdgePoints.h>
#include <multires_map_merge/GridImage.h>
#include <multires_map_merge/GroundTruthPair.h>
#include <multires_map_merge/MergeMaps.h>
#include <multires_map_merge/ros/OccupancyGridConversion.h>

#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <map>

#include "test_data.h"

namespace multires_map_merge::test
{
inline const ScanSequence& scansOf(const std::string& path)
{
	static std::map<std::string, ScanSequence> cache;
	auto it = cache.find(path);
	if (it == cache.end()) it = cache.emplace(path, loadScans(path)).first;
	return it->second;
}

inline const ScanSequence& malagaScans()
{
	return scansOf(mrptDataset("malaga-cs-fac-building.simplemap.gz"));
}

struct MsgPair
{
	GroundTruthPair grids;
	nav_msgs::OccupancyGrid ref, other;
	Similarity2D ref_origin, other_origin;  //!< grid metric frame → message frame
	/** x_ref_frame = truth(x_other_frame). */
	Similarity2D truth;
};

/** A real pair rendered by `spec`, as messages whose grids sit in frames
 * "robot1/map" and "robot2/map" at the given (rigid) origin poses. */
inline MsgPair msgPair(const PairSpec& spec, const Similarity2D& ref_origin, const Similarity2D& other_origin)
{
	MsgPair p;
	p.grids = makeGroundTruthPair(malagaScans(), spec);
	p.ref_origin = ref_origin;
	p.other_origin = other_origin;
	std_msgs::Header h1, h2;
	h1.frame_id = "robot1/map";
	h2.frame_id = "robot2/map";
	p.ref = ros1::msgFromGrid({p.grids.ref, ref_origin}, h1);
	p.other = ros1::msgFromGrid({p.grids.other, other_origin}, h2);
	p.truth = ref_origin.compose(p.grids.other_to_ref).compose(other_origin.inverse());
	return p;
}

inline PairSpec malagaSpec(double ref_res, double other_res, double yaw_deg)
{
	PairSpec spec;
	spec.ref_resolution = ref_res;
	spec.other_resolution = other_res;
	spec.other_frame = mrpt::poses::CPose2D(1.5, -2.5, yaw_deg * M_PI / 180);
	return spec;
}

inline Similarity2D rigid(double x, double y, double yaw) { return Similarity2D(1, yaw, {x, y}); }

/** The malaga 5 vs 8 cm pair with both origins rotated (ros1bridge alone
 * refuses such grids) and the frames far apart. */
inline const MsgPair& rotatedOriginsPair()
{
	static const MsgPair p = msgPair(malagaSpec(0.05, 0.08, 30), rigid(3, -1, 0.3), rigid(-20, 40, -1.0));
	return p;
}

/** The response's transform against the truth: scale and yaw, and the RMS
 * displacement of other's edge points below half a cell of the coarser map. */
inline void expectTransformMatchesTruth(const MergeMaps::Response& res, const MsgPair& p)
{
	ASSERT_TRUE(res.success) << res.message;
	const Similarity2D got(res.scale, res.transform.theta, {res.transform.x, res.transform.y});
	EXPECT_NEAR(got.scale / p.truth.scale, 1.0, 0.002);
	EXPECT_NEAR(wrapToPi(got.yaw - p.truth.yaw) * 180 / M_PI, 0.0, 0.2);
	PointList pts = edgePoints(toClassImage(p.grids.other));
	for (auto& q : pts) q = p.other_origin(cellToMetric(p.grids.other)(q));
	const double coarse = std::max(p.grids.ref.getResolution(), p.grids.other.getResolution());
	EXPECT_LT(pointRmse(got, p.truth, pts) / coarse, 0.5);
	EXPECT_NEAR(res.implied_resolution_other / p.grids.other.getResolution(), 1.0, 0.002);
	EXPECT_NEAR(
		res.scale_cells, p.grids.other.getResolution() / p.grids.ref.getResolution(),
		0.002 * res.scale_cells);
	EXPECT_GE(res.confidence, 0.5);
	EXPECT_GT(res.runtime, 0);
}

/** The merged grid: in the reference's frame, at `resolution`, covering both
 * maps (other's corners through the truth), and every occupied reference
 * cell occupied in it at the same place. */
inline void expectMergedGridIsRight(const MergeMaps::Response& res, const MsgPair& p, double resolution)
{
	ASSERT_TRUE(res.success) << res.message;
	const nav_msgs::OccupancyGrid& m = res.merged;
	EXPECT_EQ(m.header.frame_id, p.ref.header.frame_id);
	EXPECT_NEAR(m.info.resolution, resolution, 1e-6);
	ASSERT_EQ(m.data.size(), size_t(m.info.width) * m.info.height);
	const Similarity2D merged_origin = ros1::originOf(m);
	EXPECT_NEAR(wrapToPi(merged_origin.yaw - p.ref_origin.yaw), 0, 1e-6);
	const Similarity2D to_merged_cells =
		Similarity2D(1 / m.info.resolution, 0, {0, 0}).compose(merged_origin.inverse());
	auto inside = [&](const Eigen::Vector2d& world) {
		const Eigen::Vector2d c = to_merged_cells(world);
		const double tol = 1.5;  // cells: corners may round outward
		return c.x() > -tol && c.y() > -tol && c.x() < m.info.width + tol && c.y() < m.info.height + tol;
	};
	for (const auto* g : {&p.grids.ref, &p.grids.other})
		for (const double x : {g->getXMin(), g->getXMax()})
			for (const double y : {g->getYMin(), g->getYMax()})
			{
				const Eigen::Vector2d world = g == &p.grids.ref ? p.ref_origin({x, y})
																: p.truth(p.other_origin({x, y}));
				EXPECT_TRUE(inside(world)) << "corner (" << x << ", " << y << ") of "
										   << (g == &p.grids.ref ? "reference" : "other")
										   << " is outside the merged map";
			}
	const auto& ref = p.grids.ref;
	size_t occupied = 0, kept = 0;
	for (unsigned cy = 0; cy < ref.getSizeY(); ++cy)
		for (unsigned cx = 0; cx < ref.getSizeX(); ++cx)
		{
			if (occupancyProbability(ref, cx, cy) <= kOccupiedAbove) continue;
			++occupied;
			const Eigen::Vector2d c =
				to_merged_cells(p.ref_origin({ref.idx2x(cx), ref.idx2y(cy)}));
			const int mx = int(std::floor(c.x())), my = int(std::floor(c.y()));
			if (mx < 0 || my < 0 || mx >= int(m.info.width) || my >= int(m.info.height)) continue;
			if (m.data[size_t(my) * m.info.width + mx] > 50) ++kept;
		}
	ASSERT_GT(occupied, 100u);
	EXPECT_GE(double(kept) / occupied, 0.99) << kept << " of " << occupied << " occupied cells kept";
}

inline MergeMaps::Request validRequest(const MsgPair& p)
{
	MergeMaps::Request req;
	req.reference = p.ref;
	req.other = p.other;
	return req;
}

/** Columns [x0, x1) of a grid message, placed where they were. */
inline nav_msgs::OccupancyGrid cropColumns(const nav_msgs::OccupancyGrid& m, unsigned x0, unsigned x1)
{
	nav_msgs::OccupancyGrid c = m;
	c.info.width = x1 - x0;
	c.data.clear();
	for (unsigned y = 0; y < m.info.height; ++y)
		c.data.insert(c.data.end(), m.data.begin() + y * m.info.width + x0, m.data.begin() + y * m.info.width + x1);
	const Eigen::Vector2d corner = ros1::originOf(m)({x0 * m.info.resolution, 0.0});
	c.info.origin.position.x = corner.x();
	c.info.origin.position.y = corner.y();
	return c;
}

/** A request spoilt one way, and what the refusal must say (any of the
 * '|'-separated phrases). */
struct BadRequest
{
	const char* what;
	std::function<void(MergeMaps::Request&)> spoil;
	const char* says;
};

inline bool saysAnyOf(const std::string& message, const std::string& phrases)
{
	size_t from = 0;
	while (true)
	{
		const size_t bar = phrases.find('|', from);
		if (message.find(phrases.substr(from, bar - from)) != std::string::npos) return true;
		if (bar == std::string::npos) return false;
		from = bar + 1;
	}
}

/** Every bad input the service must refuse (issue: "the node must never die"),
 * applied to a valid request of the maps of msgPair. */
inline std::vector<BadRequest> badRequests()
{
	const double nan = std::numeric_limits<double>::quiet_NaN();
	const double inf = std::numeric_limits<double>::infinity();
	// Real maps of another building, and a part of the same run that the
	// reference (the first 60 % of the scans) never saw.
	static const nav_msgs::OccupancyGrid other_building = [] {
		const auto& loc = scansOf(mrptDataset("localization_demo.simplemap.gz"));
		std_msgs::Header h;
		h.frame_id = "robot3/map";
		return ros1::msgFromGrid({renderGrid(loc, 0, loc.size(), 0.08), rigid(0, 0, 0)}, h);
	}();
	// Two ends of one building, 5 and 8 cm, sharing no cell.
	static const std::pair<nav_msgs::OccupancyGrid, nav_msgs::OccupancyGrid> disjoint = [] {
		const auto& s = malagaScans();
		std_msgs::Header h;
		h.frame_id = "robot4/map";
		const auto a = ros1::msgFromGrid({renderGrid(s, 0, s.size(), 0.05), rigid(0, 0, 0)}, h);
		const auto b = ros1::msgFromGrid({renderGrid(s, 0, s.size(), 0.08), rigid(0, 0, 0)}, h);
		return std::pair{cropColumns(a, 0, a.info.width * 2 / 5), cropColumns(b, b.info.width * 3 / 5, b.info.width)};
	}();
	return {
		{"short data", [](auto& r) { r.other.data.pop_back(); }, "data has"},
		{"long data", [](auto& r) { r.reference.data.push_back(0); }, "data has"},
		{"zero width",
		 [](auto& r) {
			 r.other.info.width = 0;
			 r.other.data.clear();
		 },
		 "empty grid"},
		{"empty message", [](auto& r) { r.reference = nav_msgs::OccupancyGrid(); }, "empty grid"},
		{"zero resolution", [](auto& r) { r.other.info.resolution = 0; }, "resolution"},
		{"negative resolution", [](auto& r) { r.other.info.resolution = -0.05f; }, "resolution"},
		{"NaN resolution", [=](auto& r) { r.reference.info.resolution = nan; }, "resolution"},
		{"infinite resolution", [=](auto& r) { r.reference.info.resolution = inf; }, "resolution"},
		{"NaN origin", [=](auto& r) { r.other.info.origin.position.x = nan; }, "not finite"},
		{"NaN orientation", [=](auto& r) { r.other.info.origin.orientation.z = nan; }, "not finite"},
		{"tilted origin",
		 [](auto& r) {
			 r.other.info.origin.orientation.x = 0.3;
			 r.other.info.origin.orientation.w = 0.95;
		 },
		 "tilts"},
		{"value 101", [](auto& r) { r.reference.data[7] = 101; }, "cell value 101"},
		{"value -2", [](auto& r) { r.other.data[3] = -2; }, "cell value -2"},
		{"all unknown",
		 [](auto& r) { std::fill(r.other.data.begin(), r.other.data.end(), int8_t(-1)); }, "all unknown"},
		{"all free",
		 [](auto& r) { std::fill(r.reference.data.begin(), r.reference.data.end(), int8_t(0)); },
		 "no occupied cells"},
		{"too small for features",
		 [](auto& r) {
			 r.other.info.width = r.other.info.height = 5;
			 r.other.data.assign(25, 100);
		 },
		 "too small"},
		{"negative output resolution", [](auto& r) { r.output_resolution = -0.1; }, "output_resolution"},
		{"NaN output resolution", [=](auto& r) { r.output_resolution = nan; }, "output_resolution"},
		{"different buildings", [](auto& r) { r.other = other_building; },
		 "not confident|no consistent feature matches|no hypothesis"},
		{"non-overlapping parts",
		 [](auto& r) {
			 r.reference = disjoint.first;
			 r.other = disjoint.second;
		 },
		 "not confident|no consistent feature matches|no hypothesis"},
	};
}

}  // namespace multires_map_merge::test
