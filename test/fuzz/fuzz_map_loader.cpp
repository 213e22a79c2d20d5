// libFuzzer target: the map loaders on arbitrary bytes. The contract under
// test: loadGridMap returns a valid grid or throws MapIOError; anything else
// (another exception, a crash, a sanitizer report) is a bug.
// Input: byte 0 picks the file kind, the rest is its content:
//   0 .gridmap   1 .gridmap.gz   2 .yaml (image: a fixed valid PGM)   3 .pgm (yaml fixed)
#include <multires_map_merge/MapIO.h>

#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

using namespace multires_map_merge;

namespace
{
const std::string dir = "/tmp/mmm_fuzz_loader_" + std::to_string(getpid());

void write(const std::string& path, const uint8_t* data, size_t size)
{
	std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(data), size);
}

void write(const std::string& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

// The fixed halves of the yaml/pgm pairs.
const std::string kPgm = "P5\n4 3\n255\n" + std::string(12, '\xfe');
const std::string kYaml =
	"image: fuzz.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n";
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
	if (size < 1) return 0;
	static const bool made = std::filesystem::create_directories(dir) || true;
	(void)made;
	std::string path;
	switch (data[0] % 4)
	{
		case 0: path = dir + "/fuzz.gridmap"; break;
		case 1: path = dir + "/fuzz.gridmap.gz"; break;
		case 2:
			path = dir + "/fuzz.yaml";
			write(dir + "/fuzz.pgm", kPgm);
			break;
		default:
			path = dir + "/fuzz.yaml";
			write(path, kYaml);
			write(dir + "/fuzz.pgm", data + 1, size - 1);
			break;
	}
	if (data[0] % 4 != 3) write(path, data + 1, size - 1);
	try
	{
		const auto g = loadGridMap(path).grid;
		if (g.getSizeX() == 0 || g.getSizeY() == 0 || !(g.getResolution() > 0)) __builtin_trap();
	}
	catch (const MapIOError&)
	{
	}
	return 0;
}
