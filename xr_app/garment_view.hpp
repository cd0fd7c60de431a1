// The simulated garment of `drape pattern --simulate` as pictures: its fit map (ease and strain
// on the cloth, front and back, drawn by the renderer with the app's colour maps) and a scene
// file that `drape render --scene F --window` opens to show it in a window.
#pragma once

#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "sim/core/cloth.hpp"

namespace drape::sim {
class DressForm;
}

namespace drape::app {

// How the fit map colours the cloth: ease 0 .. ease_range_m (form colour map "ease"), strain
// -strain_range .. +strain_range ("strain").
struct FitMapOptions {
  int tile_width = 480, tile_height = 640;  // pixels of each of the four views
  float ease_range_m = 0.02f;
  float strain_range = 0.05f;
  int legend_height = 120;  // pixels of the legend under the views (fit_map_legend.hpp)
};

// Writes a PNG of four views of the cloth on the form: ease front, ease back (top row), strain
// front, strain back (bottom row), and under them the legend: each map's colour bar with its
// range labelled (ease in mm, strain in %). "" or an error naming the file (or saying that this
// build has no renderer).
std::string write_fit_map(const std::string& png_path, const sim::Cloth& cloth,
                          std::shared_ptr<const sim::DressForm> form,
                          const FitMapOptions& opt = {});

// Writes the scene file (xr_app/scene_file.hpp) of the garment's glTF `gltf_name` (a file next
// to it) on the form `form` (the scene file's "form" object), coloured by ease, seen from the
// front. "" or an error naming the file.
std::string write_garment_scene(const std::string& path, const std::string& gltf_name,
                                const nlohmann::json& form, const sim::DressForm& form_model);

}  // namespace drape::app
