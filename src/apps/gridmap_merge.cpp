// gridmap-merge: aligns and fuses saved grid maps whose resolutions may
// differ (or be wrongly stated), or the last nav_msgs/OccupancyGrid on
// topics of a rosbag: two maps, or a fleet of three or more placed in the
// first one's frame. Exit codes: 0 merged (every map placed), 1 no confident
// alignment (two maps: only the JSON is written; a fleet: the maps placed
// are merged, the JSON names the others), 2 bad input or usage.
#include <multires_map_merge/CScalingGridMapAligner.h>
#include <multires_map_merge/FleetMerge.h>
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

/** A value a file option may take: not empty, not an option (TCLAP gives a
 * file option the next word even if it is one). */
bool isFileName(const std::string& value) { return !value.empty() && value[0] != '-'; }

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

/** Throws UsageError on a --output-resolution that outputResolution cannot
 * read: checked before any map is loaded, so a typo is not found only after
 * a merge. */
void checkOutputResolution(const std::string& spec) { outputResolution(spec, 1.0, 1.0); }

/** The maps, each a grid in its exact frame (a map_server origin, a ROS
 * message's info.origin; identity for .gridmap files), and their names. */
struct Inputs
{
	std::vector<GridInFrame> maps;
	std::vector<std::string> names;
};

Inputs fromFiles(const std::vector<std::string>& files, double simplemap_res)
{
	return {loadGridMaps(files, simplemap_res), files};
}

Inputs fromBag(const std::string& bag, const std::vector<std::string>& topics)
{
	Inputs in;
	for (const auto& t : topics)
		in.maps.push_back(ros1::gridFromMsg(ros1::occupancyGridsInBag(bag, t).back(), t)),
			in.names.push_back(bag + ":" + t);
	return in;
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

/** An output that cannot be written is found before the maps are loaded
 * and aligned, not after (whyNotWritable). */
void checkWritable(const std::string& option, const std::string& path)
{
	if (const std::string why = whyNotWritable(path); !why.empty())
		throw UsageError("--" + option + " '" + path + "': " + why);
}

void writeText(const std::string& path, const std::string& text)
{
	std::ofstream f(path);
	f << text;
	if (!f) throw MapIOError("'" + path + "': cannot write");
}

/** Three or more maps: every map placed in REF's frame through its most
 * confident chain of pairwise alignments (FleetMerge.h). Exit 0 when every
 * map is placed, 1 when one is not (the merged map of those placed is still
 * written, and the JSON says which and why). */
int mergeFleet(
	const Inputs& in, const CScalingGridMapAligner& aligner, const FleetParams& fleet, const std::string& outres,
	const std::string& json, const std::string& out, const std::string& png, mrpt::system::CTicTac& clock)
{
	const FleetResult r = placeFleet(in.maps, 0, aligner, fleet);
	std::cout << "aligned " << r.pairs_aligned << " pairs, skipped " << r.pairs_skipped << "\n";
	double finest = in.maps[0].grid.getResolution();
	for (size_t m = 1; m < in.maps.size(); ++m)
	{
		const FleetPlacement& p = r.maps[m];
		if (!p.placed)
		{
			std::cout << "NOT PLACED " << in.names[m] << ": " << p.message << "\n";
			continue;
		}
		const double implied = in.maps[m].grid.getResolution() * p.in_reference.scale;
		finest = std::min(finest, implied);
		std::cout << "placed " << in.names[m] << " (confidence " << p.confidence
				  << (p.parent > 0 ? ", through " + in.names[p.parent] : std::string())
				  << (p.checked_by_cycle ? ", checked by a cycle" : "") << "): x "
				  << p.in_reference.t.x() << " m, y " << p.in_reference.t.y() << " m, yaw "
				  << p.in_reference.yaw * 180 / M_PI << " deg, scale " << p.in_reference.scale
				  << "; implied resolution " << implied << " m\n";
	}
	const bool any_placed = std::any_of(r.maps.begin() + 1, r.maps.end(), [](const FleetPlacement& p) { return p.placed; });
	if (any_placed && (!out.empty() || !png.empty()))
	{
		const double res = outputResolution(outres, in.maps[0].grid.getResolution(), finest);
		const FusedFleet fused = fuseFleet(in.maps, r, 0, res);
		std::cout << "  merged map: " << fused.merged.grid.getSizeX() << "x" << fused.merged.grid.getSizeY()
				  << " cells at " << fused.merged.grid.getResolution() << " m\n";
		if (!out.empty())
		{
			const std::string note = saveGridMap(fused.merged, out);
			std::cout << "  wrote " << out << "\n";
			if (!note.empty()) std::cerr << "gridmap-merge: note: " << note << "\n";
		}
		if (!png.empty())
		{
			if (!cv::imwrite(png, fleetOverlayImage(fused.classes))) throw MapIOError("'" + png + "': cannot write PNG");
			std::cout << "  wrote " << png << "\n";
		}
	}
	if (!json.empty()) writeText(json, fleetJson(r, in.names, 0, clock.Tac()));
	return r.allPlaced() ? kMerged : kNotMerged;
}
/** What the command line asks for. */
struct Request
{
	std::vector<std::string> maps, topics;
	std::string bag, json, out, png, config, write_config, output_resolution;
	double simplemap_resolution = 0.05;
	bool parameters = false, use_resolution_metadata = false, verbose = false;
};

/** Parses the command line (throws TCLAP's exceptions, and UsageError for
 * what TCLAP lets through). */
Request parseCommandLine(int argc, char** argv)
{
	TCLAP::CmdLine cmd(
		"Merge two occupancy grid maps of possibly different resolution. The transform printed "
		"and written is the pose of OTHER's frame in REF's: x_ref = scale*R(yaw)*x_other + (x, y), "
		"metres, each map read with its own stated metadata.",
		' ', "0.1.0");
	TCLAP::UnlabeledMultiArg<std::string> maps_arg(
		"MAPS",
		"REF OTHER [OTHER ...]: the reference map and the maps to place in its frame; each .gridmap[.gz], "
		"map_server .yaml or .simplemap[.gz] (not with --bag)",
		false, "REF OTHER [OTHER ...]", cmd);
	TCLAP::ValueArg<std::string> bag_arg(
		"", "bag", "merge the last nav_msgs/OccupancyGrid on two topics of this rosbag", false, "",
		"FILE.bag", cmd);
	TCLAP::MultiArg<std::string> topics_arg(
		"", "topics", "with --bag: REF_TOPIC OTHER_TOPIC [OTHER_TOPIC ...]", false, "TOPIC", cmd);
	TCLAP::ValueArg<std::string> json_arg("", "json", "write the result as JSON", false, "", "FILE", cmd);
	TCLAP::ValueArg<std::string> out_arg(
		"", "out", "write the merged map (.gridmap.gz or .yaml + .pgm)", false, "", "FILE", cmd);
	TCLAP::ValueArg<std::string> png_arg(
		"", "png", "write an overlay PNG (black both, blue REF only, red OTHER only; a colour per map for 3+)", false, "", "FILE", cmd);
	TCLAP::ValueArg<std::string> config_arg(
		"", "config", "parameters: sections [aligner] and [fleet] (3 maps or more) of an MRPT ini file", false, "",
		"FILE.ini", cmd);
	TCLAP::ValueArg<std::string> write_config_arg(
		"", "write-config",
		"write every aligner and fleet parameter (defaults, or --config's) with its meaning as an ini file, and exit",
		false,
		"", "FILE.ini", cmd);
	TCLAP::SwitchArg parameters_arg(
		"", "parameters", "print every aligner and fleet parameter: key, default, valid range, meaning (docs/parameters.md)",
		cmd);
	TCLAP::SwitchArg metadata_arg(
		"", "use-resolution-metadata", "use the stated resolutions as a scale prior", cmd);
	TCLAP::ValueArg<std::string> outres_arg(
		"", "output-resolution", "reference (default), finest, or metres", false, "reference",
		"reference|finest|METRES", cmd);
	TCLAP::ValueArg<double> smres_arg(
		"", "simplemap-resolution", "cell size for rendering .simplemap inputs", false, 0.05, "METRES", cmd);
	TCLAP::SwitchArg verbose_arg("v", "verbose", "log each stage and hypothesis", cmd);

	cmd.setExceptionHandling(false);
	auto args = expandTopics(argc, argv);
	cmd.parse(args);
	for (const auto& m : maps_arg.getValue())  // TCLAP takes unknown flags as positionals
		if (m.size() > 1 && m[0] == '-') throw UsageError("unknown option '" + m + "'; run with --help");
	// "--json --png x.png" wrote the JSON to a file named "--png".
	for (const auto* a : {&json_arg, &out_arg, &png_arg, &config_arg, &bag_arg, &write_config_arg})
		if (a->isSet() && !isFileName(a->getValue()))
			throw UsageError("--" + a->getName() + " needs a file name, not '" + a->getValue() + "'");
	Request q;
	q.maps = maps_arg.getValue(), q.topics = topics_arg.getValue();
	q.bag = bag_arg.getValue(), q.json = json_arg.getValue(), q.out = out_arg.getValue(), q.png = png_arg.getValue();
	q.config = config_arg.getValue(), q.write_config = write_config_arg.getValue();
	q.output_resolution = outres_arg.getValue();
	q.simplemap_resolution = smres_arg.getValue();
	q.parameters = parameters_arg.getValue(), q.use_resolution_metadata = metadata_arg.getValue();
	q.verbose = verbose_arg.getValue();
	return q;
}

/** Usage errors and outputs that cannot be written, found before any map is
 * loaded (maps are not needed with --write-config). */
void checkRequest(const Request& q)
{
	const bool bag_mode = !q.bag.empty();
	if (!q.write_config.empty() && (bag_mode || !q.maps.empty()))
		throw UsageError("--write-config takes no maps: it writes the parameters and exits");
	if (bag_mode && !q.maps.empty()) throw UsageError("give either --bag FILE --topics A B or map files, not both");
	if (!bag_mode && q.write_config.empty() && q.maps.size() < 2)
		throw UsageError("give two or more map files (REF OTHER [OTHER ...]), or --bag FILE --topics REF_TOPIC OTHER_TOPIC");
	if (!bag_mode && !q.topics.empty()) throw UsageError("--topics needs --bag");
	if (bag_mode && q.topics.size() < 2)
		throw UsageError("--bag needs --topics REF_TOPIC OTHER_TOPIC [OTHER_TOPIC ...] (two or more topics)");
	if (!q.config.empty() && !std::filesystem::is_regular_file(q.config))
		throw UsageError("'" + q.config + "': no such config file");
	if (!std::isfinite(q.simplemap_resolution) || !(q.simplemap_resolution > 0))
		throw UsageError("--simplemap-resolution must be metres > 0");
	checkOutputResolution(q.output_resolution);
	if (!q.out.empty() && !hasSuffix(q.out, ".gridmap.gz") && !hasSuffix(q.out, ".gridmap") && !hasSuffix(q.out, ".yaml"))
		throw UsageError("--out must end in .gridmap.gz, .gridmap or .yaml");
	for (const auto& [option, path] : {std::pair<std::string, std::string>{"json", q.json}, {"out", q.out}, {"png", q.png}})
		if (!path.empty()) checkWritable(option, path);
	if (hasSuffix(q.out, ".yaml"))  // and its image beside it
		checkWritable("out", std::filesystem::path(q.out).replace_extension(".pgm").string());
	if (!q.write_config.empty()) checkWritable("write-config", q.write_config);
}

/** Two maps: aligned, and if merged the merged map and overlay written.
 * `r` holds the result for the JSON. */
int mergePair(
	const Inputs& in, const CScalingGridMapAligner& aligner, const Request& q, mrpt::system::CTicTac& clock,
	CScalingGridMapAligner::TReturnInfo& r)
{
	const std::string &ref_name = in.names[0], &other_name = in.names[1];
	const auto& ref = in.maps[0].grid;
	const auto& other = in.maps[1].grid;
	std::cout << "REF   " << ref_name << ": " << ref.getSizeX() << "x" << ref.getSizeY()
			  << " cells, stated " << ref.getResolution() << " m\n"
			  << "OTHER " << other_name << ": " << other.getSizeX() << "x" << other.getSizeY()
			  << " cells, stated " << other.getResolution() << " m\n";

	// Between the maps' frames, exact for any origin.
	r = aligner.alignScaled(in.maps[0], in.maps[1]);
	double res = 0;
	if (r.success) res = outputResolution(q.output_resolution, ref.getResolution(), r.implied_resolution_other);
	if (!r.success)
	{
		std::cout << "NOT MERGED: " << r.message << "\n";
		if (!q.json.empty()) writeText(q.json, toJson(r, clock.Tac()));
		return kNotMerged;
	}
	std::cout << "merged (confidence " << r.confidence << ", overlap " << r.overlap << ")\n"
			  << "  OTHER's frame in REF's: x " << r.metric.t.x() << " m, y " << r.metric.t.y()
			  << " m, yaw " << r.metric.yaw * 180 / M_PI << " deg, scale " << r.metric.scale << "\n"
			  << "  cells: " << r.cells.scale << " REF cells per OTHER cell; OTHER's implied resolution "
			  << r.implied_resolution_other << " m (stated " << other.getResolution() << " m)\n";

	if (!q.out.empty() || !q.png.empty())
	{
		const FusedMap fused = fuseGridMaps(in.maps[0], in.maps[1], r.metric, res);
		std::cout << "  merged map: " << fused.merged.grid.getSizeX() << "x" << fused.merged.grid.getSizeY()
				  << " cells at " << fused.merged.grid.getResolution() << " m\n";
		if (!q.out.empty())
		{
			const std::string note = saveGridMap(fused.merged, q.out);
			std::cout << "  wrote " << q.out << "\n";
			if (!note.empty()) std::cerr << "gridmap-merge: note: " << note << "\n";
		}
		if (!q.png.empty())
		{
			if (!cv::imwrite(q.png, overlayImage(fused.ref_classes, fused.other_classes)))
				throw MapIOError("'" + q.png + "': cannot write PNG");
			std::cout << "  wrote " << q.png << "\n";
		}
	}
	if (!q.json.empty()) writeText(q.json, toJson(r, clock.Tac()));
	return kMerged;
}

}  // namespace

int main(int argc, char** argv)
{
	CScalingGridMapAligner::TReturnInfo r;
	mrpt::system::CTicTac clock;
	std::string json;  // written on failure too, once known to be a file name
	try
	{
		const Request q = parseCommandLine(argc, argv);
		json = q.json;
		if (q.parameters)
		{
			std::cout << alignerParamsMarkdown() << "\nSection `[fleet]` (three maps or more):\n\n" << fleetParamsMarkdown();
			return kMerged;
		}
		checkRequest(q);
		CScalingGridMapAligner aligner;
		FleetParams fleet;
		if (!q.config.empty())
		{
			const mrpt::config::CConfigFile ini(q.config);
			aligner.options.loadFromConfigFile(ini, "aligner");
			fleet.loadFromConfigFile(ini, "fleet");
		}
		if (q.use_resolution_metadata) aligner.options.use_resolution_metadata = true;
		if (q.verbose) aligner.setMinLoggingLevel(mrpt::system::LVL_DEBUG);
		if (!q.write_config.empty())
		{
			mrpt::config::CConfigFile ini(q.write_config);
			aligner.options.saveToConfigFile(ini, "aligner");
			fleet.saveToConfigFile(ini, "fleet");
			ini.writeNow();
			std::cout << "wrote " << q.write_config << "\n";
			return kMerged;
		}

		const Inputs in = q.bag.empty() ? fromFiles(q.maps, q.simplemap_resolution) : fromBag(q.bag, q.topics);
		// A .gridmap holds no rotation: say so before any work.
		if (in.maps[0].origin.yaw != 0 && !q.out.empty() && !hasSuffix(q.out, ".yaml"))
			throw UsageError(
				"--out: " + in.names[0] + " has a rotated origin, which only a .yaml map can hold; save as .yaml");
		if (in.maps.size() == 2) return mergePair(in, aligner, q, clock, r);
		for (size_t m = 0; m < in.maps.size(); ++m)
			std::cout << (m ? "OTHER " : "REF   ") << in.names[m] << ": " << in.maps[m].grid.getSizeX() << "x"
					  << in.maps[m].grid.getSizeY() << " cells, stated " << in.maps[m].grid.getResolution() << " m\n";
		return mergeFleet(in, aligner, fleet, q.output_resolution, q.json, q.out, q.png, clock);
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
		if (isFileName(json))
		{
			try
			{
				writeText(json, toJson(r, clock.Tac()));
			}
			catch (const std::exception&)
			{
			}
		}
		return kBadInput;
	}
}
