// libFuzzer target: the aligner on two small arbitrary grids. The contract:
// alignScaled never throws and never crashes; a merge it reports has a finite
// transform with a positive scale and a confidence in [0, 1].
// Input: per grid, width-8, height-8 (bytes, mod 57), a resolution byte,
// then one byte per cell (mod 3: occupied, free, unknown).
#include <multires_map_merge/CScalingGridMapAligner.h>

#include <cstdint>

using namespace multires_map_merge;
using mrpt::maps::COccupancyGridMap2D;

namespace
{
bool readGrid(const uint8_t*& p, const uint8_t* end, COccupancyGridMap2D& g)
{
	if (end - p < 3) return false;
	const unsigned w = 8 + p[0] % 57, h = 8 + p[1] % 57;
	const float res = 0.01f * (1 + p[2] % 20);
	p += 3;
	g.setSize(0, w * res, 0, h * res, res);
	for (unsigned y = 0; y < g.getSizeY(); ++y)
		for (unsigned x = 0; x < g.getSizeX(); ++x)
		{
			const uint8_t v = p < end ? *p++ : 2;
			g.setCell(x, y, v % 3 == 0 ? 0.0f : (v % 3 == 1 ? 1.0f : 0.5f));
		}
	return true;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
	const uint8_t *p = data, *end = data + size;
	COccupancyGridMap2D a, b;
	if (!readGrid(p, end, a) || !readGrid(p, end, b)) return 0;
	CScalingGridMapAligner aligner;
	aligner.setMinLoggingLevel(mrpt::system::LVL_ERROR);
	aligner.options.ransac_iterations = 200;  // keeps executions fast; the code paths are the same
	const auto r = aligner.alignScaled(a, b);
	if (!(r.confidence >= 0 && r.confidence <= 1)) __builtin_trap();
	if (r.success && !(r.metric.isFinite() && r.metric.scale > 0)) __builtin_trap();
	return 0;
}
