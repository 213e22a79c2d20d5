#include "context.h"

#include <multires_map_merge/Decision.h>

#include <mrpt/config/CConfigFile.h>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

extern char** environ;

namespace multires_bench
{
namespace fs = std::filesystem;
using namespace multires_map_merge;

CScalingGridMapAligner BenchContext::aligner() const
{
	CScalingGridMapAligner a;
	a.options = options;
	return a;
}

std::string BenchContext::tempDir(const std::string& what) const
{
	return (fs::temp_directory_path() / ("multires_bench_" + what + "_" + std::to_string(getpid()))).string();
}

std::string candidateHeader()
{
	std::string header =
		"site,ref,other,positive,calibration,index,right,error,initial_error,scale,yaw_deg,centre_x,centre_y,overlap,"
		"rmse_coarse,consistency,screened,mirrored,score,confidence";
	for (const auto& f : evidenceFields()) header += std::string(",") + f.name;
	return header + "\n";
}

Similarity2D bentFinished(
	const BenchContext& ctx, const PreparedMap& ref, const PreparedMap& other,
	const CScalingGridMapAligner::TCandidate& c)
{
	const auto& o = ctx.options;
	const Similarity2D finished = finishBent(
		ref, other, preparedCells(ref, c.cells, other), o.decision.exactConfidence(c.evidence), o.finishParams(),
		o.decision);
	return gridCells(ref, finished, other);
}

std::pair<double, bool> noTruth(const Similarity2D&) { return {NAN, false}; }

void writeCandidates(
	const BenchContext& ctx, const std::string& site, const std::string& ref, const std::string& other, bool positive,
	bool calibration, const CScalingGridMapAligner::TReturnInfo& r, const ErrorOf& error_of,
	const ReportedOf& reported_of)
{
	if (!ctx.candidates) return;
	std::ostream& out = *ctx.candidates;
	for (size_t i = 0; i < r.candidates.size(); ++i)
	{
		const auto& c = r.candidates[i];
		// A mirrored candidate (mirror_check) is a transform of the flipped map: never right.
		const bool judge = positive && !c.mirrored;
		const auto [err, right] = judge ? error_of(reported_of ? reported_of(c) : c.cells) : std::pair<double, bool>{NAN, false};
		const auto init = judge ? error_of(c.initial_cells) : std::pair<double, bool>{NAN, false};
		out << site << "," << ref << "," << other << "," << positive << "," << calibration << "," << i << "," << right
			<< "," << err << "," << init.first << "," << c.cells.scale << "," << c.cells.yaw * 180 / M_PI << ","
			<< c.other_centre.x() << "," << c.other_centre.y() << "," << c.overlap << "," << c.rmse_coarse_cells << ","
			<< c.consistency << "," << c.screened << "," << c.mirrored << "," << c.score << "," << c.confidence;
		for (const auto& f : evidenceFields()) out << "," << c.evidence.*f.member;
		out << "\n";
	}
}

double peakRssMb()
{
	std::ifstream status("/proc/self/status");
	for (std::string line; std::getline(status, line);)
		if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024;
	return NAN;
}

pid_t spawnSelf(std::vector<std::string> args, const std::string& out_path)
{
	std::vector<char*> argv;
	for (auto& a : args) argv.push_back(a.data());
	argv.push_back(nullptr);
	posix_spawn_file_actions_t fa;
	posix_spawn_file_actions_init(&fa);
	posix_spawn_file_actions_addopen(&fa, 1, out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
	pid_t pid;
	const bool started = posix_spawn(&pid, args[0].c_str(), &fa, nullptr, argv.data(), environ) == 0;
	posix_spawn_file_actions_destroy(&fa);
	return started ? pid : -1;
}

void BenchContext::loadConfig(const std::string& path)
{
	if (!fs::is_regular_file(path)) throw std::runtime_error("'" + path + "': no such config file");
	const mrpt::config::CConfigFile file(path);
	options.loadFromConfigFile(file, "aligner");
	fleet.loadFromConfigFile(file, "fleet");
	config = path;
}

std::vector<std::string> BenchContext::selfWith(std::vector<std::string> args) const
{
	args.insert(args.begin(), self);
	if (!config.empty()) args.insert(args.end(), {"--config", config});
	return args;
}

void runSelf(const std::vector<std::string>& args, const std::string& out_path)
{
	const pid_t pid = spawnSelf(args, out_path);
	if (pid < 0) throw std::runtime_error("cannot start " + args[0]);
	int status = 0;
	waitpid(pid, &status, 0);
}

std::string num(double v, int prec)
{
	if (!std::isfinite(v)) return "–";
	std::ostringstream s;
	s << std::fixed << std::setprecision(prec) << v;
	return s.str();
}

std::string cm(double res) { return num(res * 100, 0); }

std::string machine()
{
	std::ifstream cpu("/proc/cpuinfo");
	std::string line, model = "unknown CPU";
	while (std::getline(cpu, line))
		if (line.rfind("model name", 0) == 0)
		{
			model = line.substr(line.find(':') + 2);
			break;
		}
	return model + ", " + std::to_string(sysconf(_SC_NPROCESSORS_ONLN)) + " cores";
}

}  // namespace multires_bench
