// gridmap-merge: aligns and fuses two saved grid maps whose resolutions may
// differ (or be wrongly stated), or the last nav_msgs/OccupancyGrid on two
// topics of a rosbag. Exit codes: 0 merged, 1 no confident alignment (only
// the JSON is written), 2 bad input or usage.
#include <multires_map_merge/CScalingGridMapAligner.h>
#include <multires_map_merge/GridMapFusion.h>
#include <multires_map_merge/MapIO.h>
#include <multires_map_merge/MergeReport.h>
#include <multires_map_merge/ros/BagMaps.h>
#include <multires_map_merge/ros/OccupancyGridConversion.h>

#include <mrpt/config/CConfigFile.h>
#include <mrpt/system/CTicTac.h>
#include <opencv2/imgcodecs.hpp>
#include <tclap/CmdLine.h>

#include <filesystem>
#include <fstream>
#include <iostream>

using namespace multires_map_merge;

namespace
{
constexpr int kMerged = 0, kNotMerged = 1, kBadInput = 2;

struct UsageError : std::runtime_error
{
	using std::runtime_error::runtime_error;
};

double outputResolution(const std::string& spec, double ref_res, double other_res_implied)
{
	if (spec == "reference") return ref_res;
	if (spec == "finest") return std::min(ref_res, other_res_implied);
	try
	{
		size_t used = 0;
		const double v = std::stod(spec, &used);
		if (used == spec.size() && std::isfinite(v) && v > 0) return v;
	}
	catch (const std::exception&)
	{
	}
	throw UsageError("--output-resolution must be 'reference', 'finest' or metres > 0, not '" + spec + "'");
}

/** Two maps, each a grid in its exact frame: a map_server origin, a ROS
 * message's info.origin (identity for .gridmap files). */
struct Inputs
{
	GridInFrame ref, other;
};

Inputs fromFiles(const std::string& ref, const std::string& other, double simplemap_res)
{
	return {loadGridMap(ref, simplemap_res), loadGridMap(other, simplemap_res)};
}

Inputs fromBag(const std::string& bag, const std::vector<std::string>& topics)
{
	return {ros1::gridFromMsg(ros1::occupancyGridsInBag(bag, topics[0]).back(), topics[0]),
			ros1::gridFromMsg(ros1::occupancyGridsInBag(bag, topics[1]).back(), topics[1])};
}

/** TCLAP takes one value per flag: "--topics A B" becomes "--topics A --topics B". */
std::vector<std::string> expandTopics(int argc, char** argv)
{
	std::vector<std::string> args(argv, argv + argc);
	for (size_t i = 0; i + 2 < args.size(); ++i)
		if (args[i] == "--topics" && args[i + 2].rfind("-", 0) != 0)
		{
			args.insert(args.begin() + i + 2, "--topics");
			i += 2;
		}
	return args;
}

void writeText(const std::string& path, const std::string& text)
{
	std::ofstream f(path);
	f << text;
	if (!f) throw MapIOError("'" + path + "': cannot write");
}
}  // namespace

int main(int argc, char** argv)
{
	TCLAP::CmdLine cmd(
		"Merge two occupancy grid maps of possibly different resolution. The transform printed "
		"and written is the pose of OTHER's frame in REF's: x_ref = scale*R(yaw)*x_other + (x, y), "
		"metres, each map read with its own stated metadata.",
		' ', "0.1.0");
	TCLAP::UnlabeledMultiArg<std::string> maps_arg(
		"MAPS",
		"REF OTHER: the reference map and the map to align onto it; each .gridmap[.gz], "
		"map_server .yaml or .simplemap[.gz] (not with --bag)",
		false, "REF OTHER", cmd);
	TCLAP::ValueArg<std::string> bag_arg(
		"", "bag", "merge the last nav_msgs/OccupancyGrid on two topics of this rosbag", false, "",
		"FILE.bag", cmd);
	TCLAP::MultiArg<std::string> topics_arg(
		"", "topics", "with --bag: REF_TOPIC OTHER_TOPIC", false, "TOPIC", cmd);
	TCLAP::ValueArg<std::string> json_arg("", "json", "write the result as JSON", false, "", "FILE", cmd);
	TCLAP::ValueArg<std::string> out_arg(
		"", "out", "write the merged map (.gridmap.gz or .yaml + .pgm)", false, "", "FILE", cmd);
	TCLAP::ValueArg<std::string> png_arg(
		"", "png", "write an overlay PNG (black both, blue REF only, red OTHER only)", false, "", "FILE", cmd);
	TCLAP::ValueArg<std::string> config_arg(
		"", "config", "aligner parameters, section [aligner] of an MRPT ini file", false, "", "FILE.ini", cmd);
	TCLAP::SwitchArg metadata_arg(
		"", "use-resolution-metadata", "use the stated resolutions as a scale prior", cmd);
	TCLAP::ValueArg<std::string> outres_arg(
		"", "output-resolution", "reference (default), finest, or metres", false, "reference",
		"reference|finest|METRES", cmd);
	TCLAP::ValueArg<double> smres_arg(
		"", "simplemap-resolution", "cell size for rendering .simplemap inputs", false, 0.05, "METRES", cmd);
	TCLAP::SwitchArg verbose_arg("v", "verbose", "log each stage and hypothesis", cmd);

	CScalingGridMapAligner::TReturnInfo r;
	mrpt::system::CTicTac clock;
	try
	{
		cmd.setExceptionHandling(false);
		auto args = expandTopics(argc, argv);
		cmd.parse(args);
		for (const auto& m : maps_arg.getValue())  // TCLAP takes unknown flags as positionals
			if (m.size() > 1 && m[0] == '-') throw UsageError("unknown option '" + m + "'; run with --help");
		const bool bag_mode = bag_arg.isSet();
		if (bag_mode && !maps_arg.getValue().empty())
			throw UsageError("give either --bag FILE --topics A B or two map files, not both");
		if (!bag_mode && maps_arg.getValue().size() != 2)
			throw UsageError("give two map files (REF OTHER), or --bag FILE --topics REF_TOPIC OTHER_TOPIC");
		if (!bag_mode && topics_arg.isSet()) throw UsageError("--topics needs --bag");
		if (bag_mode && topics_arg.getValue().size() != 2)
			throw UsageError("--bag needs --topics REF_TOPIC OTHER_TOPIC (two topics)");

		CScalingGridMapAligner aligner;
		if (config_arg.isSet())
		{
			if (!std::filesystem::is_regular_file(config_arg.getValue()))
				throw UsageError("'" + config_arg.getValue() + "': no such config file");
			aligner.options.loadFromConfigFile(mrpt::config::CConfigFile(config_arg.getValue()), "aligner");
		}
		if (metadata_arg.getValue()) aligner.options.use_resolution_metadata = true;
		if (verbose_arg.getValue()) aligner.setMinLoggingLevel(mrpt::system::LVL_DEBUG);
		if (!std::isfinite(smres_arg.getValue()) || !(smres_arg.getValue() > 0))
			throw UsageError("--simplemap-resolution must be metres > 0");
		if (out_arg.isSet() && !hasSuffix(out_arg.getValue(), ".gridmap.gz") &&
			!hasSuffix(out_arg.getValue(), ".gridmap") && !hasSuffix(out_arg.getValue(), ".yaml"))
			throw UsageError("--out must end in .gridmap.gz, .gridmap or .yaml");

		const std::string ref_name = bag_mode ? bag_arg.getValue() + ":" + topics_arg.getValue()[0]
											  : maps_arg.getValue()[0];
		const std::string other_name = bag_mode ? bag_arg.getValue() + ":" + topics_arg.getValue()[1]
												: maps_arg.getValue()[1];
		const Inputs in = bag_mode ? fromBag(bag_arg.getValue(), topics_arg.getValue())
								   : fromFiles(ref_name, other_name, smres_arg.getValue());
		// A .gridmap holds no rotation: say so before any work.
		if (in.ref.origin.yaw != 0 && out_arg.isSet() && !hasSuffix(out_arg.getValue(), ".yaml"))
			throw UsageError(
				"--out: " + ref_name + " has a rotated origin, which only a .yaml map can hold; save as .yaml");
		const auto& ref = in.ref.grid;
		const auto& other = in.other.grid;
		std::cout << "REF   " << ref_name << ": " << ref.getSizeX() << "x" << ref.getSizeY()
				  << " cells, stated " << ref.getResolution() << " m\n"
				  << "OTHER " << other_name << ": " << other.getSizeX() << "x" << other.getSizeY()
				  << " cells, stated " << other.getResolution() << " m\n";

		// Between the maps' frames, exact for any origin.
		r = aligner.alignScaled(in.ref, in.other);
		double res = 0;
		if (r.success) res = outputResolution(outres_arg.getValue(), ref.getResolution(), r.implied_resolution_other);
		if (!r.success)
		{
			std::cout << "NOT MERGED: " << r.message << "\n";
			if (json_arg.isSet()) writeText(json_arg.getValue(), toJson(r, clock.Tac()));
			return kNotMerged;
		}
		std::cout << "merged (confidence " << r.confidence << ", overlap " << r.overlap << ")\n"
				  << "  OTHER's frame in REF's: x " << r.metric.t.x() << " m, y " << r.metric.t.y()
				  << " m, yaw " << r.metric.yaw * 180 / M_PI << " deg, scale " << r.metric.scale << "\n"
				  << "  cells: " << r.cells.scale << " REF cells per OTHER cell; OTHER's implied resolution "
				  << r.implied_resolution_other << " m (stated " << other.getResolution() << " m)\n";

		if (out_arg.isSet() || png_arg.isSet())
		{
			const FusedMap fused = fuseGridMaps(in.ref, in.other, r.metric, res);
			std::cout << "  merged map: " << fused.merged.grid.getSizeX() << "x" << fused.merged.grid.getSizeY()
					  << " cells at " << fused.merged.grid.getResolution() << " m\n";
			if (out_arg.isSet())
			{
				const std::string note = saveGridMap(fused.merged, out_arg.getValue());
				std::cout << "  wrote " << out_arg.getValue() << "\n";
				if (!note.empty()) std::cerr << "gridmap-merge: note: " << note << "\n";
			}
			if (png_arg.isSet())
			{
				if (!cv::imwrite(png_arg.getValue(), overlayImage(fused.ref_classes, fused.other_classes)))
					throw MapIOError("'" + png_arg.getValue() + "': cannot write PNG");
				std::cout << "  wrote " << png_arg.getValue() << "\n";
			}
		}
		if (json_arg.isSet()) writeText(json_arg.getValue(), toJson(r, clock.Tac()));
		return kMerged;
	}
	catch (const TCLAP::ArgException& e)
	{
		std::cerr << "gridmap-merge: " << e.error() << " (" << e.argId() << ")\nrun with --help for usage\n";
		return kBadInput;
	}
	catch (const TCLAP::ExitException& e)
	{
		return e.getExitStatus();  // --help, --version
	}
	catch (const std::exception& e)
	{
		std::cerr << "gridmap-merge: " << e.what() << "\n";
		r.success = false;
		r.message = e.what();
		if (json_arg.isSet())
		{
			try
			{
				writeText(json_arg.getValue(), toJson(r, clock.Tac()));
			}
			catch (const std::exception&)
			{
			}
		}
		return kBadInput;
	}
}
