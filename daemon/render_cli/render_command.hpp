#pragma once
// procam-render: a rig's projector framebuffers drawn offline from rig.json and one
// content image, as the daemon would show them (see kUsage).
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "blend/tiled_display.hpp"
#include "core/error.hpp"

namespace procam::render_cli {

inline constexpr const char* kUsage =
    "usage: procam-render --rig RIG.json --content IMAGE (--out DIR | --mpcdi FILE) [options]\n"
    "  Draws the framebuffer of every projector of the display that rig.json describes.\n"
    "  Planar wall: the content in the largest upright rectangle of its aspect inside the\n"
    "  union of the projectors' images on the wall (or the --rect given), through each\n"
    "  projector's homography. Curved surface (projectors with poses and surface meshes,\n"
    "  the mesh files beside rig.json): the content is the image a viewer at --viewer\n"
    "  (or the rig's viewer) sees, in the largest upright rectangle inside the union of\n"
    "  the images as the viewer sees them, through each projector's lookup warp. Both\n"
    "  blended in the overlaps in linear light through each projector's measured\n"
    "  response (rig.json photometric; gamma 2.2 otherwise). Writes DIR/NAME.png per\n"
    "  projector and DIR/display.json (the display rectangle or viewer, and per\n"
    "  projector its path, homography and footprint (planar), response and gain, and\n"
    "  the post-rendering warp its pixels are drawn through (curved)).\n"
    "options:\n"
    "  --rect X,Y,Z,W,H   the display rectangle: centre (world, metres, on the wall),\n"
    "                     width and height (metres); shrunk to the content's aspect\n"
    "  --bit-depth 8|16   PNG depth (default 8: exactly the daemon's frames; 16: drawn in\n"
    "                     double precision, content ramps keep their codes)\n"
    "  --viewer X,Y,Z     the viewer's eye (world, metres): a curved display drawn for it\n"
    "  --dome FX,FY,FZ    the content is a dome master around that eye (fisheye, zenith\n"
    "                     world +Z at its centre, this front at its bottom) instead of\n"
    "                     the eye's perspective view\n"
    "  --dome-fov DEG     the dome master's field of view across its circle (default 180)\n"
    "  --geometry-only    no blending and no response correction: the geometry alone\n"
    "  --projector NAME   only this projector of the rig (repeatable; default all that\n"
    "                     map onto the display plane)\n"
    "  --mpcdi FILE       also (or, without --out, only) export the display as VESA MPCDI,\n"
    "                     2D media profile: a zip of mpcdi.xml and per projector a warp\n"
    "                     (PFM), an alpha map (16-bit PNG, gamma embedded) and a beta map;\n"
    "                     the content image gives the buffer's size (a curved display's\n"
    "                     warps hold the viewer's image: right for that viewer)\n"
    "  --help             this text\n"
    "object (shader lamps, [Raskar02] 5.2): procam-render --rig RIG.json --object MESH\n"
    "    [--texture IMAGE] --out DIR [options]\n"
    "  Paints a neutral object: MESH (PLY with vertex s t, or OBJ with vt: texture\n"
    "  coordinates) in the rig's world; IMAGE (sRGB) its look (white without one). Each\n"
    "  posed projector's\n"
    "  frame is the look corrected for distance and angle (I = L d^2 / (k cos theta)),\n"
    "  feathered across projectors (frame edges, silhouette, grazing cut-off, depth\n"
    "  discontinuities), through its measured response; k is from its measured\n"
    "  brightness (rig.json photometric) or taken equal. display.json gives the white\n"
    "  level, its units and the coverage: the area lit, the area left unlit by projectors\n"
    "  switched off, the area no projector reaches.\n"
    "  --off NAME         a projector switched off (repeatable): the others take over\n"
    "  --viewer X,Y,Z     the eye the highlight is shaded for\n"
    "  --specular S       grey Blinn-Phong highlight, 0..1 (default 0)\n"
    "  --shininess N      its exponent (default 32)\n"
    "  --light X,Y,Z      direction towards a virtual light (default: evenly lit)\n"
    "  --max-incidence D  grazing cut-off in degrees (default 60)\n"
    "  --white L          the white level (default: the brightest every projector gives)\n"
    "Exit status: 0 success, 1 failure, 2 bad command line.\n";

struct RenderArgs {
  std::filesystem::path rig, content, out;
  std::optional<blend::WorldRect> rect;
  int bit_depth = 8;
  bool geometry_only = false;
  std::vector<std::string> projectors;
  std::filesystem::path mpcdi;  // empty: no MPCDI export
  std::optional<Vec3> viewer;   // a curved display's eye
  std::optional<Vec3> dome;     // --dome: a dome master with this front
  double dome_fov_deg = 180;    // --dome-fov
  // An object to paint (shader lamps) instead of a display.
  std::filesystem::path object, texture;
  std::vector<std::string> off;
  std::optional<Vec3> light;
  double specular = 0, shininess = 32, max_incidence_deg = 60;
  std::optional<double> white;
};

// kInvalidInput (with the reason) for a bad command line.
Result<RenderArgs> parseRenderArgs(const std::vector<std::string>& args);

// Reads the rig and the content, draws and writes every framebuffer and display.json
// (with --out) and the MPCDI package (with --mpcdi). Returns display.json's document.
Result<nlohmann::json> runRender(const RenderArgs& args);

}  // namespace procam::render_cli
