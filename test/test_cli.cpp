// gridmap-merge end to end on real data: every input format, outputs, JSON
// against ground truth, exit codes.
#include <multires_map_merge/CScalingGridMapAligner.h>
#include <multires_map_merge/FleetMerge.h>
#include <multires_map_merge/GridImage.h>
#include <multires_map_merge/GroundTruthPair.h>
#include <multires_map_merge/MapIO.h>

#include <gtest/gtest.h>
#include <mrpt/config/CConfigFile.h>
#include <opencv2/imgcodecs.hpp>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "cli_run.h"
#include "test_data.h"

using namespace multires_map_merge;
using namespace multires_map_merge::test;
namespace fs = std::filesystem;

namespace
{
std::string dir()
{
	const std::string d = ::testing::TempDir() + "/cli";
	fs::create_directories(d);
	return d;
}

// A real malaga pair at 5 and 8 cm, the second rotated 150° and shifted.
const GroundTruthPair& malagaPair()
{
	static const GroundTruthPair p = [] {
		PairSpec spec;
		spec.ref_resolution = 0.05;
		spec.other_resolution = 0.08;
		spec.other_frame = mrpt::poses::CPose2D(-2.0, 3.0, 150 * M_PI / 180);
		return makeGroundTruthPair(loadScans(test::mrptDataset("malaga-cs-fac-building.simplemap.gz")), spec);
	}();
	return p;
}

void expectTransformMatchesTruth(const std::string& json)
{
	const auto& gt = malagaPair().other_to_ref;
	EXPECT_NE(json.find("\"success\": true"), std::string::npos) << json;
	EXPECT_NEAR(jsonNumber(json, "x"), gt.t.x(), 0.04);
	EXPECT_NEAR(jsonNumber(json, "y"), gt.t.y(), 0.04);
	EXPECT_NEAR(wrapToPi(jsonNumber(json, "yaw") - gt.yaw), 0, 0.2 * M_PI / 180);
	EXPECT_NEAR(jsonNumber(json, "scale"), 1.0, 0.002);
	EXPECT_NEAR(jsonNumber(json, "scale_cells"), 0.08 / 0.05, 1.6 * 0.002);
	EXPECT_NEAR(jsonNumber(json, "implied_resolution_other"), 0.08, 0.08 * 0.002);
	for (const char* k : {"overlap", "objective", "inliers", "confidence", "runtime_s"})
		EXPECT_NO_THROW(jsonNumber(json, k)) << k;
	EXPECT_NE(json.find("\"stages\": {"), std::string::npos);
	EXPECT_NE(json.find("\"error\": \"\""), std::string::npos);
}
}  // namespace

TEST(Cli, GridmapInputsAllOutputsAndJsonAgainstTruth)
{
	const std::string d = dir();
	saveGridMap(malagaPair().ref, d + "/ref.gridmap.gz");
	saveGridMap(malagaPair().other, d + "/other.gridmap.gz");
	const CliRun r = runCli(
		d + "/ref.gridmap.gz " + d + "/other.gridmap.gz --json " + d + "/a.json --out " + d +
		"/merged.gridmap.gz --png " + d + "/a.png");
	ASSERT_EQ(r.exit_code, 0) << r.output;
	EXPECT_NE(r.output.find("implied resolution"), std::string::npos) << r.output;
	expectTransformMatchesTruth(slurp(d + "/a.json"));
	const auto merged = loadGridMap(d + "/merged.gridmap.gz").grid;
	EXPECT_NEAR(merged.getResolution(), 0.05, 1e-6);  // the reference's by default
	// The union contains the reference map.
	EXPECT_LE(merged.getXMin(), malagaPair().ref.getXMin() + 1e-3);
	EXPECT_GE(merged.getYMax(), malagaPair().ref.getYMax() - 1e-3);
	const cv::Mat png = cv::imread(d + "/a.png");
	ASSERT_FALSE(png.empty());
	EXPECT_EQ(png.cols, static_cast<int>(merged.getSizeX()));
	EXPECT_EQ(png.rows, static_cast<int>(merged.getSizeY()));
}

TEST(Cli, MapServerYamlInAndOutWithFinestResolution)
{
	const std::string d = dir();
	saveGridMap(malagaPair().ref, d + "/ref.yaml");
	saveGridMap(malagaPair().other, d + "/other.yaml");
	const CliRun r = runCli(
		d + "/ref.yaml " + d + "/other.yaml --json " + d + "/b.json --out " + d +
		"/merged.yaml --output-resolution finest");
	ASSERT_EQ(r.exit_code, 0) << r.output;
	expectTransformMatchesTruth(slurp(d + "/b.json"));
	const auto merged = loadGridMap(d + "/merged.yaml").grid;
	EXPECT_NEAR(merged.getResolution(), 0.05, 1e-4);
	EXPECT_TRUE(fs::exists(d + "/merged.pgm"));
	// An explicit output resolution.
	const CliRun r2 = runCli(d + "/ref.yaml " + d + "/other.yaml --out " + d + "/m10.gridmap.gz --output-resolution 0.1");
	ASSERT_EQ(r2.exit_code, 0) << r2.output;
	EXPECT_NEAR(loadGridMap(d + "/m10.gridmap.gz").grid.getResolution(), 0.1, 1e-6);
}

TEST(Cli, SimplemapInputsRenderedAtTheGivenResolution)
{
	// The same real simplemap as both inputs: truth is identity in metres.
	const std::string sm = test::mrptDataset("localization_demo.simplemap.gz");
	const std::string d = dir();
	const CliRun r = runCli(sm + " " + sm + " --simplemap-resolution 0.06 --json " + d + "/c.json");
	ASSERT_EQ(r.exit_code, 0) << r.output;
	const std::string j = slurp(d + "/c.json");
	EXPECT_NEAR(jsonNumber(j, "x"), 0, 0.02);
	EXPECT_NEAR(jsonNumber(j, "y"), 0, 0.02);
	EXPECT_NEAR(jsonNumber(j, "scale"), 1, 0.002);
}

TEST(Cli, DifferentBuildingsExitOneAndWriteOnlyTheJson)
{
	const std::string d = dir();
	const CliRun r = runCli(
		test::mrptDataset("malaga-cs-fac-building.simplemap.gz") + " " +
		test::mrptDataset("localization_demo.simplemap.gz") + " --json " + d + "/d.json --out " + d +
		"/never.gridmap.gz --png " + d + "/never.png");
	EXPECT_EQ(r.exit_code, 1) << r.output;
	EXPECT_NE(r.output.find("NOT MERGED"), std::string::npos) << r.output;
	const std::string j = slurp(d + "/d.json");
	EXPECT_NE(j.find("\"success\": false"), std::string::npos) << j;
	EXPECT_EQ(j.find("\"error\": \"\""), std::string::npos) << j;
	EXPECT_FALSE(fs::exists(d + "/never.gridmap.gz"));
	EXPECT_FALSE(fs::exists(d + "/never.png"));
}

TEST(Cli, BadInputAndUsageExitTwoNamingTheProblem)
{
	const std::string d = dir();
	std::ofstream(d + "/garbage.gridmap.gz") << "garbage";
	saveGridMap(malagaPair().ref, d + "/ok.gridmap.gz");
	std::ofstream(d + "/bad_fleet.ini") << "[fleet]\nunsettled_tries = -2\n";
	struct Bad
	{
		std::string args, words;
	};
	for (const Bad& b : {
			 Bad{d + "/nope.gridmap.gz " + d + "/ok.gridmap.gz", "nope.gridmap.gz': no such file"},
			 Bad{d + "/ok.gridmap.gz " + d + "/garbage.gridmap.gz", "garbage.gridmap.gz': not a serialized"},
			 // Every bad file of a fleet named in one run.
			 Bad{d + "/ok.gridmap.gz " + d + "/nope.gridmap.gz " + d + "/garbage.gridmap.gz",
				 "2 maps cannot be read: '" + d + "/nope.gridmap.gz': no such file"},
			 Bad{d + "/ok.gridmap.gz " + d + "/nope.gridmap.gz " + d + "/garbage.gridmap.gz",
				 "; '" + d + "/garbage.gridmap.gz': not a serialized"},
			 Bad{d + "/ok.gridmap.gz " + d + "/ok.gridmap.gz --output-resolution fine", "--output-resolution"},
			 Bad{d + "/ok.gridmap.gz " + d + "/ok.gridmap.gz --out x.png", "--out must end"},
			 Bad{d + "/ok.gridmap.gz " + d + "/ok.gridmap.gz --config " + d + "/none.ini", "none.ini': no such config"},
			 Bad{d + "/ok.gridmap.gz " + d + "/ok.gridmap.gz --config " + d + "/bad_fleet.ini", "[fleet] unsettled_tries"},
			 Bad{d + "/ok.gridmap.gz", "OTHER"},
			 Bad{d + "/ok.gridmap.gz " + d + "/ok.gridmap.gz --bogus", "bogus"},
			 // A file option followed by another option: no file named "--png".
			 Bad{d + "/ok.gridmap.gz " + d + "/ok.gridmap.gz --json --png " + d + "/x.png", "--json needs a file name, not '--png'"},
		 })
	{
		SCOPED_TRACE(b.args);
		const CliRun r = runCli(b.args);
		EXPECT_EQ(r.exit_code, 2) << r.output;
		EXPECT_NE(r.output.find(b.words), std::string::npos) << r.output;
	}
	EXPECT_FALSE(fs::exists("--png"));
	EXPECT_FALSE(fs::exists(d + "/x.png"));
}

// An output that cannot be written, or an output resolution that cannot be
// read, stops the run before any map is loaded or aligned (REF is not even
// announced), naming the option and the file.
TEST(Cli, UnwritableOutputsExitTwoBeforeAnyWork)
{
	const std::string d = dir();
	saveGridMap(malagaPair().ref, d + "/ok.gridmap.gz");
	fs::create_directories(d + "/a_folder");
	const std::string maps = d + "/ok.gridmap.gz " + d + "/ok.gridmap.gz";
	struct Bad
	{
		std::string args, words;
	};
	for (const Bad& b : {
			 Bad{maps + " --out " + d + "/no/such/m.yaml", "--out '" + d + "/no/such/m.yaml': no folder"},
			 Bad{maps + " --png " + d + "/no/x.png", "--png '" + d + "/no/x.png': no folder"},
			 Bad{maps + " --json " + d + "/a_folder", "--json '" + d + "/a_folder': exists and is not a file"},
			 Bad{maps + " --out " + d + "/a_folder.yaml --json " + d + "/r.json --png " + d + "/a_folder",
				 "--png '" + d + "/a_folder': exists"},
			 Bad{maps + " --out " + d + "/m.yaml --output-resolution 0", "--output-resolution must be"},
		 })
	{
		SCOPED_TRACE(b.args);
		const CliRun r = runCli(b.args);
		EXPECT_EQ(r.exit_code, 2) << r.output;
		EXPECT_NE(r.output.find(b.words), std::string::npos) << r.output;
		EXPECT_EQ(r.output.find("REF "), std::string::npos) << "loaded the maps first:\n" << r.output;
	}
	EXPECT_FALSE(fs::exists(d + "/a_folder.yaml"));
	// The JSON that can be written says why nothing else was.
	std::ifstream json(d + "/r.json");
	const std::string text((std::istreambuf_iterator<char>(json)), std::istreambuf_iterator<char>());
	EXPECT_NE(text.find("a_folder': exists and is not a file"), std::string::npos) << text;
	EXPECT_FALSE(fs::exists(d + "/x.png"));
}

// docs/parameters.md's tables are the one list as gridmap-merge prints it, and
// --write-config writes every key, which loads back as the defaults.
TEST(Cli, ParametersAsReadmeListsThemAndWrittenAsAnIni)
{
	const CliRun table = runCli("--parameters");
	ASSERT_EQ(table.exit_code, 0) << table.output;
	EXPECT_NE(slurp(MMM_PARAMETERS_DOC).find(table.output), std::string::npos)
		<< "docs/parameters.md's tables differ from `gridmap-merge --parameters`; paste them:\n" << table.output;

	const std::string ini = dir() + "/written.ini";
	const CliRun written = runCli("--write-config " + ini);
	ASSERT_EQ(written.exit_code, 0) << written.output;
	const std::string text = slurp(ini);
	for (const std::string& key : alignerParamKeys()) EXPECT_NE(text.find(key + " "), std::string::npos) << key;
	CScalingGridMapAligner::TConfigParams loaded;
	loaded.loadFromConfigFile(mrpt::config::CConfigFile(ini), "aligner");
	EXPECT_EQ(loaded.xi_min, CScalingGridMapAligner::TConfigParams().xi_min);
	EXPECT_EQ(loaded.decision.threshold, CScalingGridMapAligner::TConfigParams().decision.threshold);
	for (const auto& f : fleetParamFields()) EXPECT_NE(text.find(std::string(f.key) + " "), std::string::npos) << f.key;
	FleetParams fleet;
	fleet.joint_refinement = false;
	fleet.loadFromConfigFile(mrpt::config::CConfigFile(ini), "fleet");
	EXPECT_TRUE(fleet.joint_refinement) << "the default, written and read back";
	EXPECT_EQ(runCli("--write-config " + ini + " " + ini).exit_code, 2) << "maps with --write-config";
}
