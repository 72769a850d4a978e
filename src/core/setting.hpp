#pragma once
// A user-facing setting of a struct S, declared once: its key, kind, unit,
// range and meaning, and how to read and write its field. The config file
// reader, the effective-config printout, the reference docs and the command
// line options are driven from these declarations (match_settings.hpp,
// daemon/settings.hpp), so a range or a unit cannot differ between them.
#include <cmath>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

namespace tomomap {

/// A setting's value as a config file or command line gives it.
using SettingValue = std::variant<bool, double, std::string>;

enum class SettingKind { Flag, Integer, Number, Text };

template <typename S>
struct SettingOf {
  std::string key;
  SettingKind kind = SettingKind::Number;
  std::string unit;       ///< "m", "s", "grid cells", ... (empty: none)
  double lo = 0, hi = 0;  ///< Integer and Number: the accepted range, both ends included
  std::string doc;        ///< what it does, one paragraph
  std::function<SettingValue(const S&)> get{};
  std::function<void(S&, const SettingValue&)> set{};

  bool hasRange() const { return kind == SettingKind::Integer || kind == SettingKind::Number; }
  bool inRange(double v) const { return v >= lo && v <= hi; }
};

/// A field's value as a setting holds it (numbers as double), and back.
inline SettingValue toSettingValue(bool b) { return b; }
inline SettingValue toSettingValue(const std::string& t) { return t; }
template <typename Number>
SettingValue toSettingValue(Number n) {
  return static_cast<double>(n);
}
inline void fromSettingValue(const SettingValue& v, bool& b) { b = std::get<bool>(v); }
inline void fromSettingValue(const SettingValue& v, std::string& t) { t = std::get<std::string>(v); }
template <typename Number>
void fromSettingValue(const SettingValue& v, Number& n) {
  n = static_cast<Number>(std::get<double>(v));
}

/// Makes `s` read and write the field `at` points to (a lambda S& -> T*):
/// one accessor serves both, so the field is named once. `Setting` is a
/// SettingOf<S> or a type derived from one.
template <typename Setting, typename At>
Setting& bindField(Setting& s, At at) {
  s.get = [at](const auto& c) {
    using S = std::decay_t<decltype(c)>;
    return toSettingValue(*at(const_cast<S&>(c)));  // read only
  };
  s.set = [at](auto& c, const SettingValue& v) { fromSettingValue(v, *at(c)); };
  return s;
}

/// The setting named `key` among `all` (any type with a `key`); std::logic_error if there is none.
template <typename Setting>
const Setting& findSetting(const std::vector<Setting>& all, const std::string& key) {
  for (const auto& s : all)
    if (s.key == key) return s;
  throw std::logic_error("no setting '" + key + "'");
}

/// "true", "0.05", "1000", or the text itself.
inline std::string settingText(const SettingValue& v) {
  if (const bool* b = std::get_if<bool>(&v)) return *b ? "true" : "false";
  if (const double* d = std::get_if<double>(&v)) {
    std::ostringstream o;
    if (*d == std::floor(*d) && std::abs(*d) < 1e15)
      o << static_cast<long long>(*d);  // 10000000, not 1e+07
    else
      o << *d;
    return o.str();
  }
  return std::get<std::string>(v);
}

}  // namespace tomomap
