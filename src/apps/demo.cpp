// Demo: two maps rendered from Debian's real malaga simplemap at two
// resolutions, the second in a rotated, shifted frame, aligned without using
// their resolution metadata. Prints the estimate next to the truth.
//   multires_demo [SIMPLEMAP]          align 5/8 cm and 2/10 cm pairs in-process
//   multires_demo --write DIR          write the 5/8 cm pair as DIR/ref.gridmap.gz,
//                                      DIR/other.gridmap.gz, and as two robots'
//                                      nav_msgs/OccupancyGrid in DIR/two_robots.bag
//                                      (/robot1/map, /robot2/map); print the truth
//                                      (scripts/demo.sh then runs gridmap-merge)
#include <multires_map_merge/CScalingGridMapAligner.h>
#include <multires_map_merge/GroundTruthPair.h>
#include <multires_map_merge/MapIO.h>
#include <multires_map_merge/ros/OccupancyGridConversion.h>

#include <rosbag/bag.h>

#include <filesystem>

#include <cstdio>
#include <exception>

using namespace multires_map_merge;

int main(int argc, char** argv)
{
	const std::string malaga = "/usr/share/mrpt/datasets/malaga-cs-fac-building.simplemap.gz";
	try
	{
		if (argc == 3 && std::string(argv[1]) == "--write")
		{
			const std::string dir = argv[2];
			std::filesystem::create_directories(dir);  // and writable, before the maps are rendered
			if (const std::string why = whyNotWritable(dir + "/two_robots.bag"); !why.empty())
				throw std::runtime_error("--write '" + dir + "': " + why);
			PairSpec spec;
			spec.ref_resolution = 0.05;
			spec.other_resolution = 0.08;
			spec.other_frame = mrpt::poses::CPose2D(1.5, -2.5, 30 * M_PI / 180);
			const GroundTruthPair pair = makeGroundTruthPair(loadScans(malaga), spec);
			saveGridMap(pair.ref, dir + "/ref.gridmap.gz");
			saveGridMap(pair.other, dir + "/other.gridmap.gz");
			{
				// The same maps as two robots would publish them, each in its own frame.
				rosbag::Bag bag(dir + "/two_robots.bag", rosbag::bagmode::Write);
				std_msgs::Header h;
				h.stamp = ros::Time(1);
				h.frame_id = "robot1/map";
				bag.write("/robot1/map", h.stamp, ros1::msgFromGrid({pair.ref, {}}, h));
				h.frame_id = "robot2/map";
				bag.write("/robot2/map", h.stamp, ros1::msgFromGrid({pair.other, {}}, h));
			}
			std::printf(
				"Rendered two overlapping parts of the real malaga run:\n"
				"  %s/ref.gridmap.gz   at 5 cm\n  %s/other.gridmap.gz at 8 cm, its frame rotated and shifted\n"
				"  and both in %s/two_robots.bag on /robot1/map and /robot2/map\n"
				"TRUTH: OTHER's frame in REF's: x 1.5 m, y -2.5 m, yaw 30 deg, scale 1; "
				"OTHER's resolution 0.08 m (%.4f REF cells per OTHER cell)\n\n",
				dir.c_str(), dir.c_str(), dir.c_str(), pair.otherCellsToRefCells().scale);
			return 0;
		}
		const std::string simplemap = argc > 1 ? argv[1] : malaga;
		const ScanSequence scans = loadScans(simplemap);
		std::printf("%zu keyframes from %s\n\n", scans.size(), simplemap.c_str());
		struct Demo
		{
			double ref_res, other_res, x, y, yaw_deg;
		};
		CScalingGridMapAligner aligner;
		int failures = 0;
		for (const Demo d : {Demo{0.05, 0.08, 1.5, -2.5, 30}, Demo{0.02, 0.10, -3.0, 4.0, 200}})
		{
			PairSpec spec;
			spec.ref_resolution = d.ref_res;
			spec.other_resolution = d.other_res;
			spec.other_frame = mrpt::poses::CPose2D(d.x, d.y, d.yaw_deg * M_PI / 180);
			const GroundTruthPair pair = makeGroundTruthPair(scans, spec);
			const auto r = aligner.alignScaled(pair.ref, pair.other);
			const Similarity2D truth = pair.otherCellsToRefCells();
			std::printf(
				"reference %ux%u cells at %.0f cm, other %ux%u cells at %.0f cm (metadata not used)\n",
				pair.ref.getSizeX(), pair.ref.getSizeY(), 100 * d.ref_res, pair.other.getSizeX(),
				pair.other.getSizeY(), 100 * d.other_res);
			if (!r.success)
			{
				std::printf("  NOT MERGED: %s\n\n", r.message.c_str());
				++failures;
				continue;
			}
			std::printf("                       estimated      true\n");
			std::printf("  scale (cells)     %12.5f  %10.5f\n", r.cells.scale, truth.scale);
			std::printf("  other resolution  %11.5f m  %8.5f m\n", r.implied_resolution_other, d.other_res);
			std::printf("  rotation          %10.4f deg  %7.4f deg\n", r.metric.yaw * 180 / M_PI,
						wrapToPi(d.yaw_deg * M_PI / 180) * 180 / M_PI);
			std::printf("  translation x     %11.4f m  %8.4f m\n", r.metric.t.x(), d.x);
			std::printf("  translation y     %11.4f m  %8.4f m\n", r.metric.t.y(), d.y);
			std::printf("  overlap %.2f, confidence %.2f, %d TsICP iterations, %.2f s\n\n", r.overlap,
						r.confidence, r.icp_iterations, r.executionTime);
		}
		return failures == 0 ? 0 : 1;
	}
	catch (const std::exception& e)
	{
		std::fprintf(stderr, "demo: %s\n", e.what());
		return 2;
	}
}
