#include <multires_map_merge/ros/AlignerParamsFromRos.h>

#include <mrpt/config/CConfigFile.h>
#include <mrpt/config/CConfigFileMemory.h>
#include <ros/console.h>
#include <ros/param.h>

#include <algorithm>
#include <filesystem>
#include <sstream>
#include <stdexcept>

namespace multires_map_merge::ros1
{
namespace
{
std::string asIniValue(const std::string& key, XmlRpc::XmlRpcValue& v)
{
	std::ostringstream s;
	s.precision(17);
	switch (v.getType())
	{
		case XmlRpc::XmlRpcValue::TypeBoolean:
			return static_cast<bool>(v) ? "true" : "false";
		case XmlRpc::XmlRpcValue::TypeInt:
			s << static_cast<int>(v);
			return s.str();
		case XmlRpc::XmlRpcValue::TypeDouble:
			s << static_cast<double>(v);
			return s.str();
		default:
			throw std::invalid_argument("parameter ~" + key + " must be a number or a boolean");
	}
}

/** `params` loaded from `section` of `source`; a refusal names where the
 * value came from (`origin`: the ini file, or the node's private
 * parameters) instead of an ini section the user never wrote. */
template <class Params>
void loadNaming(Params& params, const mrpt::config::CConfigFileBase& source, const std::string& section,
	const std::string& origin)
{
	try
	{
		params.loadFromConfigFile(source, section);
	}
	catch (const std::invalid_argument& e)
	{
		std::string why = e.what();
		const std::string tag = "[" + section + "] ";
		if (why.rfind(tag, 0) == 0) why.erase(0, tag.size());
		throw std::invalid_argument(origin + why);
	}
}

template <class Params>
void loadIniFile(const std::string& path, const std::string& section, Params& params)
{
	if (!std::filesystem::is_regular_file(path)) throw std::invalid_argument("~config_file '" + path + "': no such file");
	loadNaming(params, mrpt::config::CConfigFile(path), section, "~config_file '" + path + "' [" + section + "]: ");
}
}  // namespace

CScalingGridMapAligner::TConfigParams alignerParamsFromRos(
	const ros::NodeHandle& pnh, const std::vector<std::string>& node_keys)
{
	CScalingGridMapAligner::TConfigParams params;
	std::string config_file, section = "aligner";
	pnh.getParam("config_section", section);
	if (pnh.getParam("config_file", config_file) && !config_file.empty()) loadIniFile(config_file, section, params);

	const std::vector<std::string> keys = alignerParamKeys();
	mrpt::config::CConfigFileMemory overrides;
	for (const auto& key : keys)
	{
		XmlRpc::XmlRpcValue v;
		if (pnh.getParam(key, v)) overrides.write("aligner", key, asIniValue(key, v));
	}
	loadNaming(params, overrides, "aligner", "parameter " + pnh.getNamespace() + "/");

	// A misspelt key would otherwise leave its default in force unnoticed.
	std::vector<std::string> names;
	if (ros::param::getParamNames(names))
	{
		const std::string prefix = pnh.getNamespace() + "/";
		for (const auto& name : names)
		{
			if (name.compare(0, prefix.size(), prefix) != 0) continue;
			const std::string key = name.substr(prefix.size());
			const auto& fleet = fleetParamFields();
			const bool known = std::count(keys.begin(), keys.end(), key) ||
							   std::any_of(fleet.begin(), fleet.end(), [&](const auto& f) { return key == f.key; }) ||
							   std::count(node_keys.begin(), node_keys.end(), key) ||
							   key == "config_file" || key == "config_section";
			if (!known) ROS_WARN_STREAM("parameter " << name << " is not one this node reads; ignored");
		}
	}
	return params;
}

FleetParams fleetParamsFromRos(const ros::NodeHandle& pnh)
{
	FleetParams params;
	std::string config_file;
	if (pnh.getParam("config_file", config_file) && !config_file.empty()) loadIniFile(config_file, "fleet", params);
	mrpt::config::CConfigFileMemory overrides;
	for (const auto& f : fleetParamFields())
	{
		XmlRpc::XmlRpcValue v;
		if (pnh.getParam(f.key, v)) overrides.write("fleet", f.key, asIniValue(f.key, v));
	}
	loadNaming(params, overrides, "fleet", "parameter " + pnh.getNamespace() + "/");
	return params;
}

}  // namespace multires_map_merge::ros1
