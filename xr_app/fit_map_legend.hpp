// The fit map's legend (fit_map.png, garment_view.hpp): a band under the four views with the two
// colour bars the views use, each with its labelled range — ease (the cloth's distance from the
// form) from 0 to ease_range in mm, strain (the stretch of the pattern's triangles) from
// -strain_range to +strain_range in %. The bars hold the renderer's ramps (render/shaders/
// scene.frag: ramp_ease, ramp_diverging) unlit, in sRGB: the views shade the same colours.
#pragma once

#include <string>

#include "render/renderer.hpp"

namespace drape::app {

struct LegendRanges {
  float ease_range_m = 0.02f;  // the ease map's full range (its last colour: this or more)
  float strain_range = 0.05f;  // the strain map's range either side of 0
};

// Draws the legend into rows [y0, img.height) of `img` (its full width; the ease bar in the left
// half, the strain bar in the right). "" or an error naming the font file the labels need.
std::string draw_fit_map_legend(render::Image& img, int y0, const LegendRanges& ranges);

// The ramps' colours in sRGB (0..255): ease for s in [0, 1] (red tight, yellow, green, blue
// loose), strain for s in [-1, 1] (blue compressed, white, red stretched).
void ease_colour(float s, unsigned char rgb[3]);
void strain_colour(float s, unsigned char rgb[3]);

}  // namespace drape::app
