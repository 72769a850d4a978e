#pragma once
// The fleet's map as files, as `tomomap merge` and tomomapd leave it:
// fleet_map.pcd (x y z rgba label: each robot's cells in its colour and
// label), fleet_map.pgm + .yaml (the 2D grid in map_server's format) and
// fleet_map.png (the picture), each replaced atomically.
#include <string>
#include <vector>

#include "core/fleet_map.hpp"

namespace tomomap::viz {

/// The picture's two caption lines: the map `where` ("alpha's frame,
/// levelled"), its robots and cells, and the band its colours show.
std::vector<std::string> fleetMapCaption(const FleetMap& map, const FleetGrid& grid, const HeightBand& band,
                                         const std::string& where);

/// Writes DIR/fleet_map.{pcd,pgm,yaml,png}; returns DIR/fleet_map. Each file
/// is written in DIR/.fleet_map.staging and renamed over its name,
/// so that a reader finds the old file or the new one, never half of one (the
/// PGM before the YAML that names it). Throws InputError naming the file that
/// cannot be written; the files already renamed stay.
std::string writeFleetMapFiles(const std::string& dir, const FleetMap& map, const FleetGrid& grid,
                               const std::vector<std::string>& caption);

}  // namespace tomomap::viz
