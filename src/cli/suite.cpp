#include "suite.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <filesystem>
#include <set>

#include "core/types.hpp"
#include "synth/scene.hpp"

namespace tomomap::cli {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void fail(const std::string& file, const toml::source_region& at, const std::string& what) {
  throw InputError(file + ":" + std::to_string(at.begin.line) + ":" + std::to_string(at.begin.column) + ": " + what);
}

void checkKeys(const std::string& file, const toml::table& t, const std::set<std::string>& allowed,
               const std::string& where) {
  for (const auto& [key, node] : t)
    if (!allowed.count(std::string(key.str())))
      fail(file, node.source(), "unknown key '" + std::string(key.str()) + "' in " + where);
}

std::string text(const std::string& file, const toml::table& t, const std::string& key, const std::string& where,
                 const std::optional<std::string>& fallback = std::nullopt) {
  const toml::node* n = t.get(key);
  if (!n) {
    if (fallback) return *fallback;
    fail(file, t.source(), where + " needs '" + key + "'");
  }
  if (!n->is_string()) fail(file, n->source(), "'" + key + "' must be a string");
  return n->value<std::string>().value();
}

double number(const std::string& file, const toml::table& t, const std::string& key, double fallback) {
  const toml::node* n = t.get(key);
  if (!n) return fallback;
  const auto v = n->value<double>();
  if (!v || !(*v > 0)) fail(file, n->source(), "'" + key + "' must be a positive number");
  return *v;
}

template <typename T>
std::vector<T> list(const std::string& file, const toml::table& t, const std::string& key, std::vector<T> fallback) {
  const toml::node* n = t.get(key);
  if (!n) return fallback;
  const toml::array* a = n->as_array();
  if (!a || a->empty()) fail(file, n->source(), "'" + key + "' must be a non-empty list");
  std::vector<T> out;
  for (const auto& e : *a) {
    const auto v = e.value<T>();
    if (!v) fail(file, e.source(), "'" + key + "' has an element of the wrong type");
    out.push_back(*v);
  }
  return out;
}

/// Calls `each` with every table of the array of tables `key` ([[key]]) in `root`.
template <typename Each>
void forEachTable(const std::string& file, const toml::table& root, const std::string& key, Each each) {
  const toml::node* n = root.get(key);
  if (!n) return;
  const toml::array* a = n->as_array();
  if (!a) fail(file, n->source(), "'" + key + "' must be an array of tables ([[" + key + "]])");
  for (const auto& e : *a) {
    const toml::table* t = e.as_table();
    if (!t) fail(file, e.source(), "each [[" + key + "]] must be a table");
    each(*t);
  }
}

}  // namespace

std::string sequenceName(const std::string& scans) {
  fs::path p = fs::absolute(scans).lexically_normal();
  if (p.filename().empty()) p = p.parent_path();  // a trailing slash
  if (p.filename() == "scans" && p.has_parent_path()) p = p.parent_path();
  const std::string name = p.filename().string();
  return name.empty() || name == "." || name == ".." ? "sequence" : name;
}

Suite loadSuite(const std::string& path) {
  if (!fs::exists(path)) throw InputError(path + ": no such suite file");
  toml::table root;
  try {
    root = toml::parse_file(path);
  } catch (const toml::parse_error& e) {
    fail(path, e.source(), std::string(e.description()));
  }
  checkKeys(path, root, {"name", "methods", "pair", "synth", "scan", "sequence"}, "the suite");
  const fs::path base = fs::path(path).parent_path();
  auto resolve = [&](const std::string& p) {
    return fs::path(p).is_absolute() ? p : (base / p).lexically_normal().string();
  };

  Suite s;
  s.name = text(path, root, "name", "the suite", fs::path(path).stem().string());
  s.methods = list<std::string>(path, root, "methods", s.methods);
  for (const auto& m : s.methods)
    if (std::find(kEvalMethods.begin(), kEvalMethods.end(), m) == kEvalMethods.end())
      fail(path, root.get("methods")->source(),
           "unknown method '" + m + "' (use tomomap, fpfh-ransac or paper-consensus)");

  forEachTable(path, root, "pair", [&](const toml::table& t) {
    checkKeys(path, t, {"name", "target", "source", "gt_target", "gt_source", "grid", "family"}, "[[pair]]");
    SuitePair p;
    p.target = resolve(text(path, t, "target", "[[pair]]"));
    p.source = resolve(text(path, t, "source", "[[pair]]"));
    p.gt_target = resolve(text(path, t, "gt_target", "[[pair]]"));
    p.gt_source = resolve(text(path, t, "gt_source", "[[pair]]"));
    p.name = text(path, t, "name", "[[pair]]",
                  fs::path(p.source).stem().string() + " -> " + fs::path(p.target).stem().string());
    p.grid = number(path, t, "grid", p.grid);
    p.family = text(path, t, "family", "[[pair]]", "pairs");
    std::string missing;
    for (const auto* f : {&p.target, &p.source, &p.gt_target, &p.gt_source})
      if (!fs::exists(*f)) missing = *f;
    if (!missing.empty())
      s.warnings.push_back("pair '" + p.name + "' left out: " + missing + ": no such file");
    else
      s.pairs.push_back(p);
  });
  // A block's methods: a subset of the suite's.
  auto blockMethods = [&](const toml::table& t) {
    const auto methods = list<std::string>(path, t, "methods", {});
    for (const auto& m : methods)
      if (std::find(s.methods.begin(), s.methods.end(), m) == s.methods.end())
        fail(path, t.get("methods")->source(), "method '" + m + "' is not one of the suite's methods");
    return methods;
  };
  forEachTable(path, root, "synth", [&](const toml::table& t) {
    checkKeys(path, t, {"world", "seeds", "noise", "scale", "tilt", "grid", "methods"}, "[[synth]]");
    SuiteSynth y;
    y.world = text(path, t, "world", "[[synth]]");
    try {
      synth::parseWorldType(y.world);
    } catch (const InputError& bad) {
      fail(path, t.get("world")->source(), bad.what());
    }
    y.seeds = list<int64_t>(path, t, "seeds", y.seeds);
    y.noise = list<std::string>(path, t, "noise", y.noise);
    for (const auto& n : y.noise)
      if (n != "none" && n != "low" && n != "high")
        fail(path, t.get("noise")->source(), "unknown noise level '" + n + "'");
    y.scale = number(path, t, "scale", 1.0);
    y.tilt_deg = number(path, t, "tilt", 0.0);
    y.grid = number(path, t, "grid", 0.0);
    y.methods = blockMethods(t);
    s.synth.push_back(y);
  });
  forEachTable(path, root, "scan", [&](const toml::table& t) {
    checkKeys(path, t, {"file", "name", "seeds", "grid", "move", "methods"}, "[[scan]]");
    SuiteScan c;
    c.file = resolve(text(path, t, "file", "[[scan]]"));
    c.name = text(path, t, "name", "[[scan]]", fs::path(c.file).stem().string());
    c.seeds = list<int64_t>(path, t, "seeds", c.seeds);
    c.grid = number(path, t, "grid", c.grid);
    c.move = number(path, t, "move", c.move);
    c.methods = blockMethods(t);
    if (!fs::exists(c.file))
      s.warnings.push_back("scan '" + c.name + "' left out: " + c.file + ": no such file");
    else
      s.scans.push_back(c);
  });
  forEachTable(path, root, "sequence", [&](const toml::table& t) {
    checkKeys(path, t,
              {"folder", "scans", "poses", "name", "seeds", "grid", "level", "turn", "range", "move", "methods"},
              "[[sequence]]");
    SuiteSequence q;
    if (!t.get("folder") && !(t.get("scans") && t.get("poses")))
      fail(path, t.source(), "[[sequence]] needs 'folder', or 'scans' and 'poses'");
    // A folder as the shared sequences and many SLAM packages lay it out
    // (scans/ and optimized_poses.txt), or the two named apart.
    const std::string folder = text(path, t, "folder", "[[sequence]]", "");
    q.scans = resolve(text(path, t, "scans", "[[sequence]]", (fs::path(folder) / "scans").string()));
    q.poses = resolve(text(path, t, "poses", "[[sequence]]", (fs::path(folder) / "optimized_poses.txt").string()));
    q.name = text(path, t, "name", "[[sequence]]", sequenceName(q.scans));
    q.seeds = list<int64_t>(path, t, "seeds", q.seeds);
    q.grid = number(path, t, "grid", q.grid);
    if (const toml::node* n = t.get("level")) {
      if (!n->is_boolean()) fail(path, n->source(), "'level' must be true or false");
      q.level = n->value<bool>().value();
    }
    q.turn = number(path, t, "turn", q.turn);
    if (const toml::node* n = t.get("turn"); n && !(q.turn >= 0 && q.turn <= 90))
      fail(path, n->source(), "'turn' must be 0 to 90 degrees");
    if (const toml::node* n = t.get("turn"); n && q.turn != 0 && q.level)
      fail(path, n->source(), "'turn' levels each map first: leave 'level' out");
    q.range = number(path, t, "range", q.range);
    q.move = number(path, t, "move", q.move);
    q.methods = blockMethods(t);
    if (!fs::is_directory(q.scans) || !fs::exists(q.poses))
      s.warnings.push_back("sequence '" + q.name + "' left out: " + q.scans + " or " + q.poses + ": no such file");
    else
      s.sequences.push_back(q);
  });
  if (s.pairs.empty() && s.synth.empty() && s.scans.empty() && s.sequences.empty() && s.warnings.empty())
    throw InputError(path + ": the suite lists no pairs");
  return s;
}

}  // namespace tomomap::cli
