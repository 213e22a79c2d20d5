#pragma once
// Running the gridmap-merge CLI from a test, and reading its JSON.

#include <array>
#include <cstdio>
#include <fstream>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <sys/wait.h>

namespace multires_map_merge::test
{
struct CliRun
{
	int exit_code;
	std::string output;  // stdout + stderr
};

inline CliRun runCli(const std::string& args)
{
	const std::string cmd = std::string(MMM_CLI) + " " + args + " 2>&1";
	FILE* p = popen(cmd.c_str(), "r");
	std::string out;
	std::array<char, 4096> buf;
	while (p && fgets(buf.data(), buf.size(), p)) out += buf.data();
	const int status = p ? pclose(p) : -1;
	return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

inline std::string slurp(const std::string& path)
{
	std::ifstream f(path);
	std::stringstream s;
	s << f.rdbuf();
	return s.str();
}

inline double jsonNumber(const std::string& json, const std::string& key)
{
	std::smatch m;
	if (!std::regex_search(json, m, std::regex("\"" + key + "\": (-?[0-9.eE+-]+)")))
		throw std::runtime_error("no number for " + key + " in " + json);
	return std::stod(m[1]);
}

}  // namespace multires_map_merge::test
