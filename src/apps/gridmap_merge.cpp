// gridmap-merge: aligns and fuses two saved grid maps whose resolutions may
// differ (or be wrongly stated). Exit codes: 0 merged, 1 no confident
// alignment (only the JSON is written), 2 bad input or usage.
#include <multires_map_merge/CScalingGridMapAligner.h>
#include <multires_map_merge/GridMapFusion.h>
#include <multires_map_merge/MapIO.h>
#include <multires_map_merge/MergeReport.h>

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
	TCLAP::UnlabeledValueArg<std::string> ref_arg(
		"REF", "reference map: .gridmap[.gz], map_server .yaml, .simplemap[.gz]", true, "", "REF", cmd);
	TCLAP::UnlabeledValueArg<std::string> other_arg("OTHER", "map to align onto REF", true, "", "OTHER", cmd);
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
		cmd.parse(argc, argv);

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

		const auto ref = loadGridMap(ref_arg.getValue(), smres_arg.getValue());
		const auto other = loadGridMap(other_arg.getValue(), smres_arg.getValue());
		std::cout << "REF   " << ref_arg.getValue() << ": " << ref.getSizeX() << "x" << ref.getSizeY()
				  << " cells, stated " << ref.getResolution() << " m\n"
				  << "OTHER " << other_arg.getValue() << ": " << other.getSizeX() << "x" << other.getSizeY()
				  << " cells, stated " << other.getResolution() << " m\n";

		r = aligner.alignScaled(ref, other);
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
			const FusedMap fused = fuseGridMaps(ref, other, r.metric, res);
			std::cout << "  merged map: " << fused.merged.getSizeX() << "x" << fused.merged.getSizeY()
					  << " cells at " << fused.merged.getResolution() << " m\n";
			if (out_arg.isSet())
			{
				saveGridMap(fused.merged, out_arg.getValue());
				std::cout << "  wrote " << out_arg.getValue() << "\n";
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
