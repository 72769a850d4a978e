// The docs are true to the code: every option README.md and docs/cli.md show
// is one the tool takes, and the commands README.md shows run as written.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "support.hpp"

using tomomap::test::readText;
using tomomap::test::runBinary;
using tomomap::test::TempDir;

namespace {

const std::string kSource = TOMOMAP_SOURCE_DIR;

/// The lines inside ``` fences of a Markdown file, each with the heading it sits under.
struct CodeLine {
  std::string heading, text;
};

std::vector<CodeLine> codeLines(const std::string& markdown) {
  std::vector<CodeLine> lines;
  std::istringstream in(markdown);
  std::string heading;
  bool fenced = false;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("```", 0) == 0) {
      fenced = !fenced;
    } else if (fenced) {
      lines.push_back({heading, line});
    } else if (line.rfind("## ", 0) == 0) {
      heading = line;
    }
  }
  return lines;
}

/// A command line as shown, without its comment and without the brackets of optional parts.
std::vector<std::string> wordsOf(std::string line) {
  if (const auto hash = line.find(" #"); hash != std::string::npos) line.resize(hash);
  std::vector<std::string> words;
  std::istringstream in(line);
  for (std::string w; in >> w;) {
    w.erase(std::remove_if(w.begin(), w.end(), [](char c) { return c == '[' || c == ']'; }), w.end());
    if (!w.empty()) words.push_back(w);
  }
  return words;
}

/// The program and subcommand a shown line runs ("tomomap match"), or "" when it runs none of ours.
std::string commandOf(const std::vector<std::string>& words) {
  if (words.empty()) return "";
  if (words[0] == "tomomap-baseline" || words[0] == "tomomapd") return words[0];
  if (words[0] != "tomomap") return "";
  if (words.size() > 1 && words[1].rfind('-', 0) != 0) return "tomomap " + words[1];
  return "tomomap";
}

std::string binaryOf(const std::string& command) {
  if (command == "tomomap-baseline") return TOMOMAP_BASELINE_BIN;
  if (command == "tomomapd") return TOMOMAPD_BIN;
  return TOMOMAP_BIN + command.substr(std::string("tomomap").size());
}

/// The options in a piece of text: "--grid", "-q" (not "-0.3" or "x-y").
std::set<std::string> optionsIn(const std::string& text) {
  static const std::regex option(R"((^|[\s`(,|])(--?[a-zA-Z][a-zA-Z-]*))");
  std::set<std::string> found;
  for (std::sregex_iterator it(text.begin(), text.end(), option), end; it != end; ++it) found.insert((*it)[2]);
  return found;
}

/// True when `help` lists `option` as a whole word ("--json" does not count for "--js").
bool helpLists(const std::string& help, const std::string& option) {
  for (size_t at = help.find(option); at != std::string::npos; at = help.find(option, at + 1)) {
    const char before = at == 0 ? ' ' : help[at - 1];
    const char after = at + option.size() < help.size() ? help[at + option.size()] : ' ';
    if ((before == ' ' || before == ',') && !std::isalnum(static_cast<unsigned char>(after)) && after != '-')
      return true;
  }
  return false;
}

/// Options per command shown in README.md and docs/cli.md: in command lines,
/// and in the option tables under a "## `tomomap SUB`" heading of cli.md.
std::map<std::string, std::set<std::string>> documentedOptions() {
  std::map<std::string, std::set<std::string>> options;
  for (const auto* doc : {"/README.md", "/docs/cli.md"})
    for (const auto& line : codeLines(readText(kSource + doc))) {
      const auto words = wordsOf(line.text);
      const auto command = commandOf(words);
      if (command.empty()) continue;
      for (const auto& w : words)
        for (const auto& o : optionsIn(w)) options[command].insert(o);
    }
  std::istringstream cli(readText(kSource + "/docs/cli.md"));
  std::string command;
  for (std::string line; std::getline(cli, line);) {
    if (line.rfind("## `", 0) == 0) command = commandOf(wordsOf(line.substr(4, line.find('`', 4) - 4)));
    if (command.empty() || line.rfind("| `", 0) != 0) continue;
    const std::string cell = line.substr(2, line.find('|', 2) - 2);  // the table's first column names the option
    for (const auto& o : optionsIn(cell)) options[command].insert(o);
  }
  return options;
}

}  // namespace

TEST(Docs, EveryOptionTheDocsShowIsOneTheToolTakes) {
  const auto options = documentedOptions();
  for (const auto* command : {"tomomap match", "tomomap synth", "tomomap eval", "tomomap viz", "tomomap status",
                              "tomomap fleet-keys", "tomomap-baseline", "tomomapd"})
    EXPECT_TRUE(options.count(command)) << "docs show no options for " << command << ": the parser missed them";
  for (const auto& [command, shown] : options) {
    const auto help = runBinary(binaryOf(command), "--help");
    ASSERT_EQ(help.exit_code, 0) << command << " --help: " << help.output;
    for (const auto& option : shown)
      EXPECT_TRUE(helpLists(help.output, option))
          << "docs show `" << command << " " << option << "` but its --help does not list it:\n"
          << help.output;
  }
}

/// Runs the command lines of README.md's "The `tomomap` tool" and "The
/// daemon" blocks with their placeholders filled in, synth first so that the
/// others have maps; each must exit as the docs say it does.
TEST(Docs, TheReadmeCommandsRunAsShown) {
  TempDir dir;
  std::vector<std::vector<std::string>> runs;
  for (const auto& line : codeLines(readText(kSource + "/README.md"))) {
    const auto words = wordsOf(line.text);
    const auto command = commandOf(words);
    if (command.empty() || line.heading.find("## The") != 0) continue;
    if (command == "tomomapd" && std::find(words.begin(), words.end(), "--check") == words.end()) continue;  // serves
    if (command == "tomomap" && words.size() > 2 && words[2] == "|") {  // "tomomap --help | --version": two runs
      runs.push_back({words[0], words[1]});
      runs.push_back({words[0], words[3]});
    } else {
      runs.push_back(words);
    }
  }
  std::stable_partition(runs.begin(), runs.end(), [](const auto& w) { return commandOf(w) == "tomomap synth"; });
  ASSERT_GE(runs.size(), 9u) << "the README's command blocks were not found";
  ASSERT_EQ(commandOf(runs.front()), "tomomap synth");

  // A suite of one pair, the synth maps, for `eval SUITE.toml`.
  std::ofstream(dir / "suite.toml") << "name = \"docs\"\nmethods = [\"tomomap\"]\n[[pair]]\nname = \"synth\"\n"
                                    << "target = \"maps/map_0.pcd\"\nsource = \"maps/map_1.pcd\"\n"
                                    << "gt_target = \"maps/map_0-gtpose.txt\"\ngt_source = \"maps/map_1-gtpose.txt\"\n";
  int fresh = 0;
  for (const auto& words : runs) {
    const auto command = commandOf(words);
    std::string args, previous;
    const size_t first = command.find(' ') == std::string::npos ? 1 : 2;  // after "tomomap match"
    for (size_t i = first; i < words.size(); ++i) {
      std::string w = words[i];
      if (w.find('|') != std::string::npos && w[0] != '|') w = w.substr(0, w.find('|'));  // indoor|outdoor: the first
      if (command == "tomomap synth" && w == "DIR")
        w = "maps";
      else if (w == "DIR")
        w = "out" + std::to_string(fresh++);
      else if (w == "TARGET")
        w = "maps/map_0.pcd";
      else if (w == "SOURCE")
        w = "maps/map_1.pcd";
      else if (w == "P")
        w = previous == "--gt-target" ? "maps/map_0-gtpose.txt" : "maps/map_1-gtpose.txt";
      else if (w == "FILE")
        w = "result.json";
      else if (w == "N")
        w = "1";
      else if (w == "G")
        w = "0.3";  // the baseline's RANSAC in seconds, not a minute
      else if (w == "SUITE.toml")
        w = "suite.toml";
      else if (w == "STATE_DIR")
        w = "no-daemon-here";
      else if (w == "robot.toml")
        w = kSource + "/config/tomomapd.toml";
      if (w == "|") continue;
      args += " '" + w + "'";
      previous = words[i];
    }
    const auto r = runBinary("cd '" + dir.path.string() + "' && " + binaryOf(command), args);
    const std::string shown = command + args;
    if (command == "tomomap status") {  // no daemon ran here: exit 2, still one JSON document
      EXPECT_EQ(r.exit_code, 2) << shown << "\n" << r.output;
      EXPECT_NE(r.output.find("\"running\": false"), std::string::npos) << shown << "\n" << r.output;
    } else if (command == "tomomap-baseline") {  // 0 converged, 1 no reliable match: both are answers
      EXPECT_TRUE(r.exit_code == 0 || r.exit_code == 1) << shown << "\n" << r.output;
    } else {
      EXPECT_EQ(r.exit_code, 0) << shown << "\n" << r.output;
    }
  }
  EXPECT_TRUE(std::filesystem::exists(dir / "result.json"));
  EXPECT_TRUE(std::filesystem::exists(dir / "fleet/ca.pem"));
  EXPECT_TRUE(std::filesystem::exists(dir / "out0/summary.md") || std::filesystem::exists(dir / "out1/summary.md"));
}
