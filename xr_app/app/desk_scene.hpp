// The scene a live session drapes (`drape run` at a desk or on a headset): a square panel of a
// fabric preset on a dress form (a standard size, a measurements file or a scanned mesh), in one
// of the study's start states. Errors name the option and the file at fault, so the executable
// can check the choice before it opens a session.
#pragma once

#include <string>

#include "sim/core/types.hpp"
#include "sim/form/dress_form.hpp"
#include "sim/testbeds/testbed.hpp"
#include "xr_app/app/xr_app.hpp"

namespace drape::app {

// The start states (XrAppOptions::start): "spread" (the panel spread open, horizontal, sticking
// forward from the chest line; its top edge and its two free corners pinned, so it stays open
// until a hand releases them), "rolled" (rolled up from its bottom edge into a roll that rests
// on the chest line; the top edge and the roll's core pinned) and "pinned-top" (hanging from its
// top edge, pinned across the chest).
const char* desk_start_names();  // "spread|rolled|pinned-top", for messages and --help
bool is_desk_start(const std::string& name);

// The panel (0.5 m square, opt.cloth_res vertices a side, opt.fabric from opt.fabrics_path) on
// the form of opt.form_* in the start state opt.start. Errors: "--fabric: <file>: ...", "--form
// <file>: ...", "--mesh <file>: ...", "--start: ...".
sim::Result<sim::Testbed> make_desk_scene(const XrAppOptions& opt);

// The scene's form on its own: that of opt.form_*; errors as make_desk_scene's.
sim::Result<sim::DressForm> desk_form(const XrAppOptions& opt);

}  // namespace drape::app
