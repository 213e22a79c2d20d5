#pragma once
// How a parameter of a field list (key, member, range, meaning) is read,
// checked and written: in an ini file (a value that reads back exactly, its
// meaning beside it) and in docs/parameters.md's tables (its valid range). The aligner's
// and the fleet's parameter lists both go through these.
#include <mrpt/config/CConfigFileBase.h>
#include <mrpt/core/format.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <variant>

namespace multires_map_merge::param_text
{
/** The shortest text that reads back as `v` exactly: MRPT writes doubles
 * with "%f", which saved icp_relative_tolerance (1e-7) as 0. */
inline std::string exactText(double v)
{
	for (int digits = 6; digits < 17; ++digits)
		if (const std::string t = mrpt::format("%.*g", digits, v); std::stod(t) == v) return t;
	return mrpt::format("%.17g", v);
}

inline void writeKey(
	mrpt::config::CConfigFileBase& c, const std::string& s, const char* key, const std::string& value, const char* what)
{
	c.write(s, key, value, mrpt::config::MRPT_SAVE_NAME_PADDING(), mrpt::config::MRPT_SAVE_VALUE_PADDING(), what);
}

/** "[lo, hi]", or "0 or [lo, hi]" where 0 has a meaning of its own. */
inline std::string rangeText(double lo, double hi, bool zero_also)
{
	return mrpt::format("%s[%g, %g]", zero_also ? "0 or " : "", lo, hi);
}
/** A field's value as the ini file holds it. */
template <class Params, class Member>
std::string valueText(const Params& params, const Member& member)
{
	return std::visit(
		[&](auto m) -> std::string {
			const auto v = params.*m;
			if constexpr (std::is_same_v<decltype(v), const bool>) return v ? "true" : "false";
			else return exactText(double(v));
		},
		member);
}

template <class Params, class Member>
bool isBool(const Member& member)
{
	return std::holds_alternative<bool Params::*>(member);
}

/** Reads `key` of section `s` into the field (absent: unchanged). An
 * unsigned count is read as text and parsed whole, so a negative,
 * fractional, too large or non-numeric one is refused by name instead of
 * wrapping around (or reading as 0, as atof would). */
template <class Params, class Member>
void readField(Params& params, const Member& member, const mrpt::config::CConfigFileBase& c, const std::string& s,
	const char* key)
{
	std::visit(
		[&](auto m) {
			auto& v = params.*m;
			using T = std::remove_reference_t<decltype(v)>;
			if constexpr (std::is_same_v<T, bool>) v = c.read_bool(s, key, v);
			else if constexpr (std::is_same_v<T, int>) v = c.read_int(s, key, v);
			else if constexpr (std::is_floating_point_v<T>) v = c.read_double(s, key, v);
			else
			{
				const std::string text = c.read_string(s, key, "", false);
				if (text.empty()) return;
				double read = NAN;
				size_t used = 0;
				try
				{
					read = std::stod(text, &used);
				}
				catch (const std::exception&)
				{
				}
				const bool whole = used == text.size() && read >= 0 && read == std::floor(read) &&
					read < std::ldexp(1.0, std::numeric_limits<T>::digits);
				if (!whole)
					throw std::invalid_argument(
						"[" + s + "] " + key + " = " + text + " is not a count (a whole number >= 0)");
				v = static_cast<T>(read);
			}
		},
		member);
}

/** Why the field's value is out of its range ("" when it is not). */
template <class Params, class Member>
std::string outOfRange(const Params& params, const Member& member, const char* key, double lo, double hi, bool zero_also)
{
	if (isBool<Params>(member)) return "";
	const double v = std::visit([&](auto m) { return static_cast<double>(params.*m); }, member);
	if ((zero_also && v == 0) || (v >= lo && v <= hi)) return "";
	return mrpt::format("%s = %g is outside %s", key, v, rangeText(lo, hi, zero_also).c_str());
}

/** The docs/parameters.md table row of a field. */
template <class Params, class Member>
std::string markdownRow(const Params& defaults, const Member& member, const char* key, double lo, double hi,
	bool zero_also, const char* description)
{
	return std::string("| `") + key + "` | " + valueText(defaults, member) + " | " +
		(isBool<Params>(member) ? std::string("true, false") : rangeText(lo, hi, zero_also)) + " | " + description +
		" |\n";
}

}  // namespace multires_map_merge::param_text
