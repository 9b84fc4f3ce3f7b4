#pragma once
// The shader programs of the GLES 3 back-end and their uniform locations.
#include "core/error.hpp"
#include "gl/gl_objects.hpp"

namespace procam::output::gl {

// Samples a source texture at projective texture coordinates (s, t, q); transparent black
// where q <= 0 or (s, t)/q is outside [0, 1) — the footprint rule of render/bilinear.hpp.
// Two vertex front-ends: 2D pixel-space geometry (homography quad, warp grids) and world-
// space meshes (two-pass projective texture).
struct SampleProgram {
  Program program;
  GLint clip = -1;    // mat4: clip from vertex position
  GLint tex = -1;     // mat4: (s, t, q, -) from vertex source attribute
  GLint source = -1;  // sampler2D
};

// Vertex-coloured 3D triangles (planar 3D path).
struct ColorProgram {
  Program program;
  GLint clip = -1;
};

// Final stage: alpha mask, weight LUT and output LUTs in integer arithmetic
// (render/final_stage.hpp), 1:1 texel fetch from the rendered frame.
struct FinalProgram {
  Program program;
  GLint clip = -1, frame = -1, mask = -1, weight_lut = -1, output_lut = -1, has_mask = -1;
};

struct Programs {
  SampleProgram sample_2d;    // attributes: 0 vec2 pixel, 1 vec3 source
  SampleProgram sample_mesh;  // attributes: 0 vec3 world
  ColorProgram color;         // attributes: 0 vec3 world, 1 vec4 colour
  FinalProgram final_stage;   // attributes: 0 vec2 pixel
};

// Compiles and links one program from its vertex and fragment sources; kIo with the GL
// info log on failure.
Result<Program> linkProgram(const char* vs, const char* fs);

// Compiles and links every program; kIo with the GL info log on failure.
Result<Programs> buildPrograms();

}  // namespace procam::output::gl
