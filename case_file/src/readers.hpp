// The section readers of a case file (one file each: read_<section>.cpp). Private to
// case_file; load_case() (read_case.cpp) calls them in the order of the format.
#pragma once

#include <string>

#include "object_reader.hpp"
#include "pdamp/case_file/case.hpp"

namespace pdamp::case_file::detail {

/// Index of material `name` in the case's materials (the DEM's material table has the
/// same order), or a CaseError at `key` naming it.
int material_index(const ObjectReader& r, const std::string& key, const std::string& name, const Case& c);

/// Drive, gravity and closed-form constants of a damper (format 1 `damper`, format 2
/// `dampers[i]`).
void read_damper_drive(ObjectReader& r, DamperSpec& damper);
/// Container, particles, lattice and clearance of one layer (format 1: `damper`; format
/// 2: `dampers[i].layers[k]`), with the derived bed quantities under `derived`. The bed
/// sits inside layer.compartment.layer's lining (read before): its clearance is the free
/// length between the linings' surfaces.
void read_layer_bed(ObjectReader& r, const Case& c, const DamperSpec& damper, LayerSpec& layer);
/// The DEM geometry of one layer's compartment: wall material, placement, inner
/// structures, wall layer (format 1: in `dem`; format 2: in each layer).
void read_layer_geometry(ObjectReader& r, const Case& c, LayerSpec& layer);
/// Format 1's /dem/wall_layer thickness and axis as written, for the bed that is read
/// before /dem (read_layer_geometry checks them there); no layer where they are malformed.
dem_reference::WallLayerOptions provisional_wall_layer(const nlohmann::json& root);
/// A structure-plane direction [x, y] at `key`, normalised (and resolved so); CaseError
/// for a zero or non-finite one. Without `fallback` the key is required.
PlaneVector read_plane_direction(ObjectReader& r, const std::string& key, std::optional<PlaneVector> fallback);
/// The name at `key`, which must be a named point of the structure (format 2), or a
/// CaseError listing the known ones.
std::string read_point_name(ObjectReader& r, const std::string& key, const Case& c);
/// A path given in the case file at r's position, relative to the case file's folder
/// unless absolute ("" stays "").
std::string resolve_case_relative(const ObjectReader& r, const std::string& path);
/// Format 2 `dampers`, checked against the structure's point names.
void read_dampers(ObjectReader& root, Case& c);
/// `dem`: materials and contacts, numerics; format 1 also the layer geometry.
void read_dem(ObjectReader& r, Case& c);
/// `field`: the effective-field grid (defaults from the first layer's clearance).
void read_field(ObjectReader& r, Case& c);
/// Format 2 `structure`.
StructureSpec read_structure(ObjectReader& r, const Case& c);
/// Format 2 `task` (an object, or a kind's name with its defaults).
TaskSpec read_task(ObjectReader& root, const Case& c);

}  // namespace pdamp::case_file::detail
