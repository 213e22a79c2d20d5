#include "ros_maps.h"

#include "halmstad.h"

#include <multires_map_merge/Finish.h>
#include <multires_map_merge/GridImage.h>
#include <multires_map_merge/GroundTruthPair.h>
#include <multires_map_merge/MapIO.h>

#include <mrpt/system/CTicTac.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

namespace multires_bench
{
namespace fs = std::filesystem;
using namespace multires_map_merge;

const std::vector<RosPlace> kRosPlaces{
	{"troyes", "accompany_troyes_house", {"map", "PC_map", "map_TroyesDataSet"}},
	{"heerlen", "accompany_heerlen", {"heerlen_2013-06-14", "heerlen_2013-07-08"}},
	{"tb3", "robotis_turtlebot3_lds_test_area", {"tb3_map_2016-12-02", "tb3_map_2017-02-07", "tb3_map_2017-03-14"}},
};

namespace
{
constexpr int kCoarse = 4;  //!< the turn search's cells per side

struct Pose
{
	double score = -1, yaw = 0;
	Eigen::Vector2d t{0, 0};  //!< q = R(yaw) p + t, cells
};

cv::Mat occupiedField(const cv::Mat& classes, double sigma)
{
	cv::Mat field;
	cv::Mat(classes == kOccupied).convertTo(field, CV_32F, 1.0 / 255);
	cv::GaussianBlur(field, field, cv::Size(), sigma);
	return field;
}

Eigen::Matrix2d rotation(double yaw)
{
	Eigen::Matrix2d r;
	r << std::cos(yaw), -std::sin(yaw), std::sin(yaw), std::cos(yaw);
	return r;
}

/** Every turn (1°) on kCoarse× coarser images: the best shift of each by
 * correlation; the `keep` best turns at least 5° apart, in full cells. */
std::vector<Pose> coarseTurns(const cv::Mat& ref_classes, const cv::Mat& other_classes, size_t keep)
{
	cv::Mat ref_small, other_small;
	cv::resize(occupiedField(ref_classes, 0.5), ref_small, cv::Size(), 1.0 / kCoarse, 1.0 / kCoarse, cv::INTER_AREA);
	cv::resize(occupiedField(other_classes, 0.5), other_small, cv::Size(), 1.0 / kCoarse, 1.0 / kCoarse, cv::INTER_AREA);
	cv::GaussianBlur(ref_small, ref_small, cv::Size(), 1.0);
	const int side = int(std::ceil(std::hypot(other_small.cols, other_small.rows))) + 2;
	cv::Mat padded;
	cv::copyMakeBorder(ref_small, padded, side, side, side, side, cv::BORDER_CONSTANT, 0);
	const Eigen::Vector2d other_centre(other_small.cols / 2.0, other_small.rows / 2.0), canvas_centre(side / 2.0, side / 2.0);
	std::vector<Pose> turns;
	for (int deg = 0; deg < 360; ++deg)
	{
		Pose p;
		p.yaw = deg * M_PI / 180;
		const Eigen::Matrix2d r = rotation(p.yaw);
		const Eigen::Vector2d shift = canvas_centre - r * other_centre;
		const cv::Mat m = (cv::Mat_<double>(2, 3) << r(0, 0), r(0, 1), shift.x(), r(1, 0), r(1, 1), shift.y());
		cv::Mat turned, score;
		cv::warpAffine(other_small, turned, m, cv::Size(side, side), cv::INTER_LINEAR, cv::BORDER_CONSTANT, 0);
		cv::matchTemplate(padded, turned, score, cv::TM_CCORR);
		cv::Point at;
		cv::minMaxLoc(score, nullptr, &p.score, nullptr, &at);
		// Coarse other pixel v lands on ref pixel r v + shift + at − side.
		p.t = kCoarse * (shift + Eigen::Vector2d(at.x, at.y) - Eigen::Vector2d(side, side));
		turns.push_back(p);
	}
	std::sort(turns.begin(), turns.end(), [](const Pose& a, const Pose& b) { return a.score > b.score; });
	std::vector<Pose> kept;
	for (const Pose& p : turns)
	{
		const bool apart = std::all_of(kept.begin(), kept.end(), [&](const Pose& k) {
			return std::abs(std::remainder(k.yaw - p.yaw, 2 * M_PI)) > 5 * M_PI / 180;
		});
		if (apart) kept.push_back(p);
		if (kept.size() == keep) break;
	}
	return kept;
}

/** Turns within ±1.5° (0.1°) and shifts within ±(kCoarse + 2) cells about
 * the other map's occupied centroid, scored on every occupied cell. */
Pose refine(const Pose& start, const cv::Mat& ref_field, const std::vector<Eigen::Vector2d>& points)
{
	Eigen::Vector2d centroid(0, 0);
	for (const auto& p : points) centroid += p;
	centroid /= double(points.size());
	const Eigen::Vector2d centre_lands = rotation(start.yaw) * centroid + start.t;
	Pose best;
	const int reach = kCoarse + 2;
	for (int tenth = -15; tenth <= 15; ++tenth)
	{
		const double yaw = start.yaw + tenth * 0.1 * M_PI / 180;
		const Eigen::Matrix2d r = rotation(yaw);
		for (int dy = -reach; dy <= reach; ++dy)
			for (int dx = -reach; dx <= reach; ++dx)
			{
				const Eigen::Vector2d t = centre_lands + Eigen::Vector2d(dx, dy) - r * centroid;
				double score = 0;
				for (const auto& p : points)
				{
					const Eigen::Vector2d q = r * p + t;
					const int x = int(std::lround(q.x())), y = int(std::lround(q.y()));
					if (x >= 0 && y >= 0 && x < ref_field.cols && y < ref_field.rows) score += ref_field.at<float>(y, x);
				}
				if (score > best.score) best = {score, yaw, t};
			}
	}
	return best;
}

std::string yamlOf(const BenchContext& ctx, const RosPlace& place, const std::string& map)
{
	return ctx.data + "/ros_maps/" + place.dir + "/" + map + ".yaml";
}

/** Every map of every place, read once: "place/stem" → map. */
using RosMaps = std::map<std::string, GridInFrame>;

/** `map` with each cell split into `factor`² cells of its value, in the same
 * frame, written as a map_server file in `dir` and read back (as a user's
 * file would be). */
GridInFrame finerMap(const GridInFrame& map, double factor, const std::string& dir, const std::string& name)
{
	GridInFrame fine = map;
	const auto& g = map.grid;
	fine.grid.setSize(g.getXMin(), g.getXMax(), g.getYMin(), g.getYMax(), float(g.getResolution() / factor));
	for (unsigned y = 0; y < fine.grid.getSizeY(); ++y)
		for (unsigned x = 0; x < fine.grid.getSizeX(); ++x)
			fine.grid.setCell(
				x, y, g.getCell(g.x2idx(fine.grid.idx2x(x)), g.y2idx(fine.grid.idx2y(y))));
	std::string file = name;
	std::replace(file.begin(), file.end(), '/', '_');
	const std::string yaml = dir + "/" + file + ".yaml";
	if (const std::string why = saveGridMap(fine, yaml); !why.empty()) throw std::runtime_error(why);
	return loadGridMap(yaml);
}

/** One ordered pair: `truth` (metres, between the maps' frames) for a
 * positive, none for a negative; displacements in cells of `cell_m`. */
RosMapsRun runPair(
	const BenchContext& ctx, const RosMaps& maps, double factor, const std::string& ref_place,
	const std::string& ref_name, const std::string& other_name, const Similarity2D* truth, double cell_m)
{
	RosMapsRun run;
	run.factor = factor;
	run.place = ref_place;
	run.ref = ref_name, run.other = other_name;
	run.positive = truth != nullptr;
	const GridInFrame &ref = maps.at(ref_name), &other = maps.at(other_name);
	mrpt::system::CTicTac clock;
	const auto r = ctx.aligner().alignScaled(ref, other);
	run.seconds = clock.Tac();
	run.merged = r.success, run.confidence = r.confidence, run.message = r.message;
	// The calibration data holds the files' pairs only.
	const bool record = factor == 1.0;
	if (!run.positive)
	{
		if (record) writeCandidates(ctx, "ros", run.ref, run.other, false, true, r, noTruth);
	}
	else
	{
		const auto points = occupiedPointsInMapFrame(other);
		const auto displacement = [&](const Similarity2D& metric) {
			double sum = 0;
			for (const auto& p : points) sum += (metric(p) - (*truth)(p)).norm();
			return sum / std::max<size_t>(1, points.size()) / cell_m;
		};
		if (r.candidates.size())
		{
			run.displacement_cells = displacement(r.metric);
			run.right = run.merged && run.displacement_cells <= kRosRightCells;
		}
		// Each candidate judged as it would be reported (the finish), as the
		// Halmstad pairs are.
		if (record)
		{
			const auto ref_prepared = ctx.aligner().prepare(ref.grid), other_prepared = ctx.aligner().prepare(other.grid);
			writeCandidates(
				ctx, "ros", run.ref, run.other, true, true, r,
				[&](const Similarity2D& cells) {
					const double e = displacement(candidateMetric(ref, cells, other));
					return std::pair<double, bool>{e, e <= kRosRightCells};
				},
				[&](const auto& c) { return bentFinished(ctx, *ref_prepared, *other_prepared, c); });
		}
	}
	std::cout << "ros maps";
	if (factor != 1.0) std::cout << " x" << factor << " finer";
	std::cout << " " << run.ref << " <- " << run.other << ": "
			  << (run.positive ? (run.merged ? (run.right ? "merged right" : "MERGED WRONG") : "refused")
						   : (run.merged ? "MERGED (false)" : "refused (other place)"))
			  << ", " << run.displacement_cells << " cells from the truth, confidence " << run.confidence << ", "
			  << run.seconds << " s" << std::endl;
	return run;
}
}  // namespace

Similarity2D bruteForceRigid(const cv::Mat& ref_classes, const cv::Mat& other_classes)
{
	const cv::Mat ref_field = occupiedField(ref_classes, 1.0);
	std::vector<Eigen::Vector2d> points;
	for (int y = 0; y < other_classes.rows; ++y)
		for (int x = 0; x < other_classes.cols; ++x)
			if (other_classes.at<uint8_t>(y, x) == kOccupied) points.emplace_back(x, y);
	Pose best;
	for (const Pose& start : coarseTurns(ref_classes, other_classes, 3))
		if (const Pose p = refine(start, ref_field, points); p.score > best.score) best = p;
	return Similarity2D(1, best.yaw, best.t);
}

std::vector<RosMapsRun> runRosMaps(const BenchContext& ctx, const std::vector<double>& factors)
{
	RosMaps files;
	for (const RosPlace& place : kRosPlaces)
		for (const auto& m : place.maps) files.emplace(place.name + "/" + m, loadGridMap(yamlOf(ctx, place, m)));
	// The truth of each same-place pair (b's frame in a's, metres), from the files.
	std::map<std::pair<std::string, std::string>, Similarity2D> truth;
	for (const RosPlace& place : kRosPlaces)
		for (size_t a = 0; a < place.maps.size(); ++a)
			for (size_t b = a + 1; b < place.maps.size(); ++b)
			{
				const std::string ma = place.name + "/" + place.maps[a], mb = place.name + "/" + place.maps[b];
				const Similarity2D b_to_a_cells =
					bruteForceRigid(toClassImage(files.at(ma).grid), toClassImage(files.at(mb).grid));
				truth[{ma, mb}] = candidateMetric(files.at(ma), b_to_a_cells, files.at(mb));
				truth[{mb, ma}] = truth[{ma, mb}].inverse();
			}
	std::vector<RosMapsRun> runs;
	for (const double factor : factors)
	{
		RosMaps finer;
		std::string dir;
		if (factor != 1.0)
		{
			dir = ctx.tempDir("ros_finer");
			fs::create_directories(dir);
			for (const auto& [name, map] : files) finer.emplace(name, finerMap(map, factor, dir, name));
		}
		const RosMaps& maps = factor == 1.0 ? files : finer;
		for (const RosPlace& ref_place : kRosPlaces)
			for (const auto& ref : ref_place.maps)
				for (const RosPlace& other_place : kRosPlaces)
					for (const auto& other : other_place.maps)
					{
						const std::string mr = ref_place.name + "/" + ref, mo = other_place.name + "/" + other;
						if (mr == mo) continue;
						const auto t = truth.find({mr, mo});
						const double cell_m = files.at(mr).grid.getResolution();
						runs.push_back(runPair(
							ctx, maps, factor, ref_place.name, mr, mo, t == truth.end() ? nullptr : &t->second, cell_m));
					}
		if (!dir.empty()) fs::remove_all(dir);
	}
	return runs;
}

std::string rosCellsLabel(double factor)
{
	if (factor == 1.0) return "files";
	std::ostringstream label;
	label << "×" << factor << " finer";
	return label.str();
}

void writeRosMapsSection(std::ostream& md, const std::vector<RosMapsRun>& runs)
{
	md << "\n## Independent ROS maps (ros_maps, SOURCES.md 2b)\n\n"
	   << "Real map_saver maps of three places, each mapped two or three times on different days (furniture, "
		  "clutter and extent differ), read as map_server files. No annotation: a pair's truth is the rigid transform "
		  "a brute-force search over every turn and shift finds (`bruteForceRigid`, bench/ros_maps.h). **Right** = "
		  "merged with the other map's occupied cells within "
	   << kRosRightCells
	   << " cells of the files (mean) of the truth. Every ordered pair of a place, and every map against every map of "
		  "the other places (must not merge). Calibration data (`--calibration-data`, site `ros`): the files' pairs. "
		  "*Finer*: every map resampled "
	   << kRosFinerFactor
	   << "× finer (each cell split into cells of its value), written as map_server files stated at that "
		  "resolution and read back: a lab mapped at 2 cm is in cells what a place "
	   << kRosFinerFactor
	   << "× larger is at 5 cm (its walls keep their thickness, 2–3 cells, where a 2 cm lidar map draws them "
		  "thinner). Never calibrated on.\n\n"
	   << "| cells | place | pairs | merged right | refused | merged wrong | displacement of the right [cells of the files] | other places' maps merged | median time [s] |\n"
	   << "|---|---|---|---|---|---|---|---|---|\n";
	std::set<double> factors;
	for (const auto& r : runs) factors.insert(r.factor);
	for (const double factor : factors)
		for (const RosPlace& place : kRosPlaces)
		{
			size_t pairs = 0, right = 0, refused = 0, wrong = 0, negatives = 0, false_merges = 0;
			std::vector<double> disp, secs;
			for (const auto& r : runs)
			{
				if (r.place != place.name || r.factor != factor) continue;
				secs.push_back(r.seconds);
				if (!r.positive)
				{
					++negatives, false_merges += r.merged;
					continue;
				}
				++pairs;
				if (!r.merged) ++refused;
				else if (r.right) ++right, disp.push_back(r.displacement_cells);
				else ++wrong;
			}
			const auto [lo, hi] = disp.empty()
				? std::pair<double, double>{NAN, NAN}
				: std::pair<double, double>{*std::min_element(disp.begin(), disp.end()),
											*std::max_element(disp.begin(), disp.end())};
			char range[64];
			std::snprintf(range, sizeof range, disp.empty() ? "–" : "%.1f–%.1f", lo, hi);
			char time[32];
			std::snprintf(time, sizeof time, "%.2f", median(secs));
			md << "| " << rosCellsLabel(factor) << " | " << place.name << " | " << pairs << " | " << right << " | " << refused << " | " << wrong << " | "
			   << range << " | " << false_merges << " / " << negatives << " | " << time << " |\n";
		}
}

}  // namespace multires_bench
