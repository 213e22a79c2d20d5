// fleet-bag: records a multi-robot mapping session as a rosbag, rendered from
// a real laser log: three robots map overlapping shares of one run at 5, 3
// and 8 cm, each in its own frame, the third joining late (and, with
// --other-log, a fourth robot in another building). Their maps grow step by
// step as full maps and map updates: what `roslaunch multires_map_merge
// fleet_demo.launch` plays through the map_merge node. Prints the truth.
#include <multires_map_merge/MapIO.h>
#include <multires_map_merge/ros/FleetBag.h>

#include <tclap/CmdLine.h>

#include <cmath>
#include <iostream>

using namespace multires_map_merge;

int main(int argc, char** argv)
{
	TCLAP::CmdLine cmd("Record a multi-robot session (growing maps at different resolutions) as a rosbag", ' ', "0.1.0");
	TCLAP::ValueArg<std::string> out_arg("", "out", "the bag to write", true, "", "FILE.bag", cmd);
	TCLAP::ValueArg<std::string> log_arg(
		"", "log", "the run the robots share (.simplemap[.gz] or CARMEN .log[.gz])", false,
		"/usr/share/mrpt/datasets/malaga-cs-fac-building.simplemap.gz", "FILE", cmd);
	TCLAP::ValueArg<std::string> other_arg("", "other-log", "a run of another building for a fourth robot", false, "", "FILE", cmd);
	TCLAP::ValueArg<int> steps_arg("", "steps", "steps of map growth", false, 6, "N", cmd);
	TCLAP::ValueArg<double> period_arg("", "period", "seconds between steps", false, 2.0, "S", cmd);
	try
	{
		cmd.parse(argc, argv);
		// Found before the maps are rendered, not after.
		if (const std::string why = whyNotWritable(out_arg.getValue()); !why.empty())
			throw std::invalid_argument("--out '" + out_arg.getValue() + "': " + why);
		const double deg = M_PI / 180;
		std::vector<ros1::FleetBagRobot> robots = {
			{"/robot1", log_arg.getValue(), 0.0, 0.6, 0.05, {}, 0},
			{"/robot2", log_arg.getValue(), 0.3, 0.9, 0.03, {2.0, -1.0, 40 * deg}, 0},
			{"/robot3", log_arg.getValue(), 0.5, 1.0, 0.08, {-1.5, 3.0, -120 * deg}, 2},
		};
		if (other_arg.isSet()) robots.push_back({"/robot4", other_arg.getValue(), 0.0, 0.6, 0.05, {}, 1});
		ros1::writeFleetBag(out_arg.getValue(), robots, steps_arg.getValue(), period_arg.getValue());
		std::cout << "wrote " << out_arg.getValue() << " (" << steps_arg.getValue() << " steps, "
				  << period_arg.getValue() << " s apart). The truth, each robot's map frame in robot1's:\n";
		for (const auto& r : robots)
			std::cout << "  " << r.name << " (" << r.resolution * 100 << " cm, joins at step " << r.join_step
					  << "): " << (r.log == log_arg.getValue()
								   ? "x " + std::to_string(r.frame.x()) + " m, y " + std::to_string(r.frame.y()) +
										" m, yaw " + std::to_string(r.frame.phi() / deg) + " deg"
								   : "another building: must stay out")
					  << "\n";
		return 0;
	}
	catch (const TCLAP::ArgException& e)
	{
		std::cerr << "fleet-bag: " << e.error() << " (" << e.argId() << ")\n";
		return 2;
	}
	catch (const std::exception& e)
	{
		std::cerr << "fleet-bag: " << e.what() << "\n";
		return 2;
	}
}
