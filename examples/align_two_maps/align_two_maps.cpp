// Aligns two saved maps (map_server .yaml, .gridmap(.gz), .simplemap) and
// prints where OTHER lies in REF's frame: x_ref = scale·R(yaw)·x_other + (x, y).
// Exit 0 merged, 1 not confident (the reason printed), 2 bad input.
#include <multires_map_merge/CScalingGridMapAligner.h>
#include <multires_map_merge/MapIO.h>

#include <cmath>
#include <iostream>

int main(int argc, char** argv)
{
	if (argc != 3)
	{
		std::cerr << "usage: align_two_maps REF OTHER\n";
		return 2;
	}
	try
	{
		const auto ref = multires_map_merge::loadGridMap(argv[1]);
		const auto other = multires_map_merge::loadGridMap(argv[2]);
		multires_map_merge::CScalingGridMapAligner aligner;
		const auto r = aligner.alignScaled(ref, other);
		if (!r.success)
		{
			std::cout << "not merged: " << r.message << "\n";
			return 1;
		}
		std::cout << "x " << r.metric.t.x() << " m, y " << r.metric.t.y() << " m, yaw "
				  << r.metric.yaw * 180 / M_PI << " deg, scale " << r.metric.scale << ", confidence "
				  << r.confidence << "\n";
		return 0;
	}
	catch (const std::exception& e)  // MapIOError names the file and the problem
	{
		std::cerr << "align_two_maps: " << e.what() << "\n";
		return 2;
	}
}
