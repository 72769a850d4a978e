// `tomomap match TARGET SOURCE`: offline registration of two map files.
#include "commands.hpp"
#include "match_files.hpp"

namespace tomomap::cli {

Command addMatchCommand(CLI::App& app) {
  auto o = std::make_shared<MatchFilesOptions>();
  CLI::App* sub =
      app.add_subcommand("match", "Find T_target_source between two map files (PCD, PLY, XYZ/CSV text, OctoMap).");
  sub->add_option("TARGET", o->target, "target map (.pcd, .ply, .xyz/.txt/.csv, OctoMap .bt/.ot)")->required();
  sub->add_option("SOURCE", o->source, "source map, to be moved into the target frame")->required();
  addMatchOptions(*sub, *o);
  sub->footer("Exit codes: 0 reliable match, 1 no reliable match, 2 bad input, 3 internal error.");
  return {sub, [o] {
            const MatchedFiles m = matchFiles(*o);
            return report(m.result, m.truth, o->params.grid, {o->json, "tomomap", o->quiet, o->candidates}, m.inputs);
          }};
}

}  // namespace tomomap::cli
