// `tomomap match TARGET SOURCE`: offline registration of two map files.
#include "commands.hpp"
#include "match_files.hpp"

namespace tomomap::cli {

Command addMatchCommand(CLI::App& app) {
  struct Options {
    MatchFilesOptions files;
    std::string json;
  };
  auto o = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand("match", "Find T_target_source between two map files (PCD, PLY, XYZ).");
  sub->add_option("TARGET", o->files.target, "target map (.pcd, .ply, .xyz/.txt)")->required();
  sub->add_option("SOURCE", o->files.source, "source map, to be moved into the target frame")->required();
  sub->add_option("--json", o->json, "also write the result as JSON to FILE");
  addMatchOptions(*sub, o->files);
  sub->footer("Exit codes: 0 reliable match, 1 no reliable match, 2 bad input, 3 internal error.");
  return {sub, [o] {
            const MatchedFiles m = matchFiles(o->files);
            return report(m.result, m.P_target, m.P_source, o->files.params.grid, o->json, false, m.sizes);
          }};
}

}  // namespace tomomap::cli
