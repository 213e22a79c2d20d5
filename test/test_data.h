#pragma once
// Where the tests find real data. Debian's mrpt-common datasets exist on every
// machine after set-up; ../shared/data exists on developer machines and in CI.
// Outside CI a missing shared folder skips those tests; in CI it fails them.

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <string>

namespace multires_map_merge::test
{
inline std::string mrptDataset(const std::string& name)
{
	return std::string(MMM_MRPT_DATASETS) + "/" + name;
}

inline bool inCI()
{
	const char* ci = std::getenv("CI");
	return ci && std::string(ci) != "" && std::string(ci) != "0" && std::string(ci) != "false";
}

inline bool fileExists(const std::string& p) { return std::ifstream(p).good(); }

/** Path into ../shared/data, or "" (after recording a skip or, in CI, a
 * failure) when it is missing. */
inline std::string sharedData(const std::string& rel)
{
	const std::string p = std::string(MMM_SHARED_DATA) + "/" + rel;
	if (fileExists(p)) return p;
	if (inCI()) ADD_FAILURE() << "shared data missing in CI: " << p;
	return "";
}

}  // namespace multires_map_merge::test

#define MMM_REQUIRE_SHARED(var, rel)                                            \
	const std::string var = ::multires_map_merge::test::sharedData(rel);        \
	if (var.empty())                                                            \
	{                                                                           \
		if (::multires_map_merge::test::inCI()) return;                         \
		GTEST_SKIP() << "../shared/data not found (" << rel << ")";            \
	}
