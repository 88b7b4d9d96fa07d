// pmr_gl_bench: the conventional way to make a multi-view display image, for comparison with pmr
// (docs/PERFORMANCE.md, "Against OpenGL (Mesa llvmpipe)"). OpenGL 3.3 core on Mesa's llvmpipe (the
// same CPU pmr runs on), one pass per view into a (multisampled) framebuffer, each view resolved into a
// tile of a view atlas (a quilt), then the display encoding as a fragment shader and one glReadPixels.
// The scene is loaded by pmr's own loader and the cameras and display come from a pmr sidecar, so both
// programs draw the same triangles, materials and textures with the same matrices and view map, shaded
// as the sidecar's frame was (lambert, or pbr with the uniform environment). Not a test: it times frames.
#define GL_GLEXT_PROTOTYPES 1
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/glcorearb.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfMultiPartOutputFile.h>
#include <ImfOutputPart.h>
#include <ImfPartType.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <glm/gtc/type_ptr.hpp>
#include <nlohmann/json.hpp>

#include "pmr/rig.h"
#include "pmr/scene.h"
#include "shading/environment.h"

namespace {

struct Options {
  std::string scene, sidecar, out;
  int msaa = 4, frames = 5;
  bool mipmap = true;
  bool float_encoder = false;  // --encoder float
};

const char* kUsage =
    "usage: pmr_gl_bench SCENE --sidecar FRAME.json [--msaa 0|4] [--frames K] [--no-mipmap]\n"
    "                     [--encoder tables|float] [--out DIR]\n"
    "  SCENE: the glTF file pmr rendered; FRAME.json: that render's sidecar (cameras, display, shading)\n"
    "  --msaa 0|4: samples per pixel of the view framebuffer (compare with pmr --samples 1|4); default 4\n"
    "  --frames K: timed frames after one warm-up frame; default 5\n"
    "  --no-mipmap: sample textures bilinearly without mip-maps, as pmr does (image comparisons)\n"
    "  --encoder tables: pmr's exact view map from its tables (default); float: computed per subpixel in\n"
    "    float arithmetic, as typical interlacing shaders do (no subpixel cells)\n"
    "  --out DIR: write DIR/gl_encoded.exr and DIR/gl_views.exr (parts view_000...) after timing\n";

Options parse_options(int argc, char** argv) {
  Options o;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    auto value = [&]() -> std::string {
      if (a + 1 >= argc) throw std::runtime_error(arg + " needs a value");
      return argv[++a];
    };
    if (arg == "--sidecar") o.sidecar = value();
    else if (arg == "--msaa") o.msaa = std::stoi(value());
    else if (arg == "--frames") o.frames = std::stoi(value());
    else if (arg == "--out") o.out = value();
    else if (arg == "--no-mipmap") o.mipmap = false;
    else if (arg == "--encoder") {
      const std::string e = value();
      if (e != "tables" && e != "float") throw std::runtime_error("--encoder takes tables or float");
      o.float_encoder = e == "float";
    } else if (arg == "--help" || arg == "-h") throw std::runtime_error("");
    else if (!arg.empty() && arg[0] == '-') throw std::runtime_error("unknown option " + arg);
    else o.scene = arg;
  }
  if (o.scene.empty() || o.sidecar.empty()) throw std::runtime_error("SCENE and --sidecar are required");
  if (o.msaa != 0 && o.msaa != 4) throw std::runtime_error("--msaa takes 0 or 4");
  if (o.frames < 1) throw std::runtime_error("--frames takes a positive count");
  return o;
}

// What the GL renderer takes from a pmr sidecar (docs/OUTPUTS.md; host/output/sidecar.cpp).
struct Frame {
  int views = 0, view_w = 0, view_h = 0, samples = 1;
  int quilt_columns = 1, quilt_rows = 1;   // the view atlas's tiles
  std::vector<glm::mat4> clip_from_world;  // proj * view per view, multiplied in double
  std::vector<glm::vec3> eyes;             // each view's camera position, world space (pbr)
  glm::vec3 light_world{0.0f};             // toward Lambert's light
  pmr::Display display;
  std::string scene, sampling, shading;
  float exposure = 1.0f;  // 2^EV
  // pbr: the lights as pmr used them (world space) and the uniform environment's radiance
  std::vector<pmr::SceneLight> lights;
  float env_radiance = 0.0f;
};

// pbr's lights and environment from the sidecar's "shading" (host/output/sidecar.cpp, shading_json).
void read_pbr_inputs(const nlohmann::json& shading, Frame& f) {
  const nlohmann::json& env = shading.at("environment");
  if (env.at("kind").get<std::string>() != "uniform")
    throw std::runtime_error(
        "pbr with the studio or an environment image is not implemented here: render the "
        "sidecar's frame with --environment uniform");
  f.env_radiance = env.at("radiance").get<float>();
  for (const nlohmann::json& j : shading.at("lights")) {
    pmr::SceneLight l;
    const std::string type = j.at("type").get<std::string>();
    l.type = type == "point"  ? pmr::SceneLightType::Point
             : type == "spot" ? pmr::SceneLightType::Spot
                              : pmr::SceneLightType::Directional;
    for (int c = 0; c < 3; ++c) l.color[c] = j.at("color").at(c).get<float>();
    l.intensity = j.at("intensity").get<float>();
    if (j.contains("position")) l.position = glm::dvec3(j["position"][0], j["position"][1], j["position"][2]);
    if (j.contains("direction")) l.direction = glm::dvec3(j["direction"][0], j["direction"][1], j["direction"][2]);
    if (j.contains("range") && j["range"].is_number()) l.range = j["range"].get<float>();
    l.inner_cone = j.value("inner_cone_angle", 0.0f), l.outer_cone = j.value("outer_cone_angle", 0.7853981634f);
    f.lights.push_back(l);
  }
  if (f.lights.size() > 8) throw std::runtime_error("more than 8 lights are not implemented here");
}

// The display exactly as pmr encoded it: its fractions, so that make_encode_tables gives pmr's own
// subpixel-to-view map.
pmr::Display display_from_sidecar(const nlohmann::json& d) {
  pmr::Display out;
  out.width = d.at("width").get<int>();
  out.height = d.at("height").get<int>();
  out.lens_pitch = pmr::parse_rational(d.at("lens_pitch_fraction").get<std::string>(), "lens_pitch");
  out.tan_slant = pmr::parse_rational(d.at("tan_slant_fraction").get<std::string>(), "tan_slant");
  out.offset = pmr::parse_rational(d.at("offset_fraction").get<std::string>(), "offset");
  out.reversed = d.at("reversed").get<bool>();
  out.phase_sign = d.at("phase_sign").get<int>();
  out.subpixel_bgr = d.at("subpixel_order").get<std::string>() == "bgr";
  if (d.contains("cell_rows")) {
    out.cell_rows = d.at("cell_rows").get<int>();
    out.cell_offsets = d.at("cell_offsets_1e14").get<std::vector<int64_t>>();
  }
  out.bilinear = d.at("sampling").get<std::string>() == "bilinear";
  out.blend_views = d.at("view_blend").get<bool>();
  return out;
}

glm::dmat4 matrix_from_json(const nlohmann::json& a) {
  const std::vector<double> m = a.get<std::vector<double>>();
  if (m.size() != 16) throw std::runtime_error("a sidecar matrix without 16 numbers");
  return glm::make_mat4(m.data());  // column-major, as the sidecar stores it
}

Frame read_sidecar(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  const nlohmann::json j = nlohmann::json::parse(in);
  Frame f;
  const nlohmann::json& rig = j.at("rig");
  f.views = rig.at("views").get<int>();
  f.view_w = rig.at("view_width").get<int>();
  f.view_h = rig.at("view_height").get<int>();
  f.samples = j.value("samples_per_pixel", 1);
  // the squarest quilt: the likeliest to fit GL's texture size limit (checked by create_view_targets)
  for (f.quilt_columns = 1; f.quilt_columns < f.views; ++f.quilt_columns)
    if (f.quilt_columns * f.view_w >= (f.views + f.quilt_columns - 1) / f.quilt_columns * f.view_h) break;
  f.quilt_rows = (f.views + f.quilt_columns - 1) / f.quilt_columns;
  f.scene = j.value("scene", "");
  f.sampling = j.value("sampling", "view");
  f.shading = j.contains("shading") ? j["shading"].value("model", "lambert") : "lambert";
  if (j.contains("shading")) f.exposure = float(std::exp2(j["shading"].value("exposure_ev", 0.0)));
  if (f.shading == "pbr") read_pbr_inputs(j.at("shading"), f);
  else if (f.shading != "lambert") throw std::runtime_error("unknown shading " + f.shading);
  for (const nlohmann::json& v : j.at("views")) {
    const glm::dmat4 view = matrix_from_json(v.at("view"));
    f.clip_from_world.push_back(glm::mat4(matrix_from_json(v.at("proj")) * view));
    f.eyes.push_back(glm::vec3(glm::inverse(view)[3]));
  }
  if (int(f.clip_from_world.size()) != f.views) throw std::runtime_error("the sidecar's views do not match rig.views");
  const std::vector<double> l = j.at("light_dir_world").get<std::vector<double>>();
  f.light_world = glm::vec3(float(l.at(0)), float(l.at(1)), float(l.at(2)));
  f.display = display_from_sidecar(j.at("display"));
  if (f.display.blend_views) throw std::runtime_error("view blending (display.view_blend) is not implemented here");
  return f;
}

// Software rendering on every core, unless the caller chose otherwise: llvmpipe's rasterizer threads
// are the GL side's only parallelism, as PoCL's threads are pmr's.
void select_llvmpipe() {
  setenv("LIBGL_ALWAYS_SOFTWARE", "1", 0);
  setenv("GALLIUM_DRIVER", "llvmpipe", 0);
  setenv("LP_NUM_THREADS", std::to_string(std::max(1u, std::thread::hardware_concurrency())).c_str(), 0);
}

// A surfaceless EGL display (no window system: runs on a headless machine) with a current OpenGL 3.3
// core context. Everything renders into framebuffer objects.
// No display or context: the test that runs this skips (tests/bench/gl_smoke.sh), it does not fail.
struct NoContext : std::runtime_error {
  using std::runtime_error::runtime_error;
};
constexpr int kExitNoContext = 77;

void create_context() {
  select_llvmpipe();
  EGLDisplay dpy = eglGetPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  EGLint major = 0, minor = 0;
  if (dpy == EGL_NO_DISPLAY || !eglInitialize(dpy, &major, &minor))
    throw NoContext("no surfaceless EGL display (Mesa's EGL_MESA_platform_surfaceless)");
  if (!eglBindAPI(EGL_OPENGL_API)) throw NoContext("EGL cannot bind desktop OpenGL");
  // no config (EGL_KHR_no_config_context): nothing is drawn to an EGL surface
  const EGLConfig config = EGL_NO_CONFIG_KHR;
  const EGLint context_attribs[] = {
      EGL_CONTEXT_MAJOR_VERSION,           3,       EGL_CONTEXT_MINOR_VERSION, 3, EGL_CONTEXT_OPENGL_PROFILE_MASK,
      EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
  EGLContext ctx = eglCreateContext(dpy, config, EGL_NO_CONTEXT, context_attribs);
  if (ctx == EGL_NO_CONTEXT) throw NoContext("no OpenGL 3.3 core context");
  if (!eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx)) throw NoContext("eglMakeCurrent failed");
}

// Throws the info log of a shader that did not compile or a program that did not link.
void check_built(GLuint object, bool program) {
  GLint ok = 0;
  if (program) glGetProgramiv(object, GL_LINK_STATUS, &ok);
  else glGetShaderiv(object, GL_COMPILE_STATUS, &ok);
  if (ok) return;
  char log[4096] = "";
  if (program) glGetProgramInfoLog(object, sizeof log, nullptr, log);
  else glGetShaderInfoLog(object, sizeof log, nullptr, log);
  throw std::runtime_error(std::string(program ? "program: " : "shader: ") + log);
}

GLuint compile(GLenum type, const char* source) {
  const GLuint s = glCreateShader(type);
  glShaderSource(s, 1, &source, nullptr);
  glCompileShader(s);
  check_built(s, false);
  return s;
}

GLuint link(const char* vertex, const char* fragment) {
  const GLuint p = glCreateProgram();
  glAttachShader(p, compile(GL_VERTEX_SHADER, vertex));
  glAttachShader(p, compile(GL_FRAGMENT_SHADER, fragment));
  glLinkProgram(p);
  check_built(p, true);
  return p;
}

// The vertex stage passes the world-space attributes on; every texture slot applies its own texCoord set
// and KHR_texture_transform in the fragment stage (an affine map: the same as interpolating its result).
const char* kSceneVertex = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec4 color;
layout(location = 3) in vec2 uv0;
layout(location = 4) in vec2 uv1;
layout(location = 5) in vec4 tangent;
uniform mat4 clip_from_world;
out vec3 v_position, v_normal;
out vec4 v_color, v_tangent;
out vec2 v_uv0, v_uv1;
void main() {
  v_position = position;
  v_normal = normal;
  v_color = color;
  v_tangent = tangent;
  v_uv0 = uv0;
  v_uv1 = uv1;
  gl_Position = clip_from_world * vec4(position, 1.0);
}
)";

// DESIGN section 4a (lambert): base = baseColorFactor x baseColorTexture x COLOR_0, colour = base (0.2 +
// 0.8 max(0, n . l)). Section 4b (pbr, cl/shade.h and cl/brdf.h): metallic-roughness GGX with the
// normal, occlusion and emissive maps, the punctual lights of the sidecar and the uniform environment
// through pmr's split-sum table. n is flipped on back faces (only double-sided materials show them),
// alpha = coverage, colours times 2^EV and at most 65504 (half).
const char* kSceneFragment = R"(#version 330 core
in vec3 v_position, v_normal;
in vec4 v_color, v_tangent;
in vec2 v_uv0, v_uv1;
struct Slot { bool on; int set; vec3 u, v; };  // u' = dot(u, (u, v, 1)), v' = dot(v, (u, v, 1))
uniform Slot slots[5];                         // base colour, metallic-roughness, normal, occlusion, emissive
uniform sampler2D maps[5];
uniform vec4 base_factor;
uniform bool mask, pbr, unlit;
uniform float cutoff, exposure, metallic_factor, roughness_factor, normal_scale, occlusion_strength;
uniform vec3 emissive_factor, light, eye;
uniform int light_count;
uniform int light_type[8];  // 0 directional, 1 point, 2 spot
uniform vec3 light_color[8], light_position[8], light_direction[8];
uniform float light_range[8], light_cos_inner[8], light_cos_outer[8];
uniform float env_radiance;
uniform sampler2D split_sum;  // 64 x 64 (A, B)
out vec4 frag;
const float PI = 3.14159265358979;
vec4 sample_slot(sampler2D map, int k) {  // samplers: constant indices only
  vec3 uv = vec3(slots[k].set == 0 ? v_uv0 : v_uv1, 1.0);
  return texture(map, vec2(dot(slots[k].u, uv), dot(slots[k].v, uv)));
}
vec3 mapped_normal(vec3 n) {
  vec3 t = v_tangent.xyz - n * dot(n, v_tangent.xyz);
  float len = length(t);
  vec3 s = sample_slot(maps[2], 2).xyz;
  vec3 m = vec3((2.0 * s.xy - 1.0) * normal_scale, 2.0 * s.z - 1.0);
  if (len <= 1e-12) return n;
  t /= len;
  vec3 mapped = t * m.x + cross(n, t) * (v_tangent.w < 0.0 ? -1.0 : 1.0) * m.y + n * m.z;
  return length(mapped) > 0.0 ? normalize(mapped) : n;
}
vec3 brdf_cos(vec3 base, float metallic, float r, vec3 n, vec3 v, vec3 l) {
  float nl = clamp(dot(n, l), 0.0, 1.0), nv = clamp(dot(n, v), 0.0, 1.0);
  vec3 hv = l + v;
  float hl = length(hv);
  vec3 h = hl > 0.0 ? hv / hl : n;
  float nh = clamp(dot(n, h), 0.0, 1.0), vh = clamp(dot(v, h), 0.0, 1.0);
  float a2 = r * r * r * r;
  vec3 f0 = mix(vec3(0.04), base, metallic);
  float k = 1.0 - vh, k5 = k * k * k * k * k;
  vec3 F = f0 + (1.0 - f0) * k5;
  float d = nh * nh * (a2 - 1.0) + 1.0, D = a2 / (PI * d * d);
  float sv = nl * sqrt(nv * nv * (1.0 - a2) + a2) + nv * sqrt(nl * nl * (1.0 - a2) + a2);
  float spec = D * (sv > 0.0 ? 0.5 / sv : 0.0);
  vec3 f = (1.0 - F) * base * (1.0 - metallic) / PI + F * spec;
  return nl > 0.0 ? f * nl : vec3(0.0);
}
vec3 irradiance_from(int i, vec3 p, out vec3 l) {
  if (light_type[i] == 0) { l = -light_direction[i]; return light_color[i]; }
  vec3 d = light_position[i] - p;
  float d2 = dot(d, d), dist = sqrt(d2);
  l = d2 > 0.0 ? d / dist : vec3(0.0);
  float w = d2 > 0.0 ? 1.0 / d2 : 0.0;
  if (light_range[i] > 0.0) { float q = dist / light_range[i]; w *= clamp(1.0 - q * q * q * q, 0.0, 1.0); }
  if (light_type[i] == 2) {
    float c = -dot(light_direction[i], l);
    float s = clamp((c - light_cos_outer[i]) / max(0.001, light_cos_inner[i] - light_cos_outer[i]), 0.0, 1.0);
    w *= s * s;
  }
  return light_color[i] * w;
}
vec2 split_sum_at(float nv, float r) {  // pmr's bilinear lookup (split_sum_lanes)
  const int N = 64;
  float x = sqrt(clamp(nv, 0.0, 1.0)) * float(N - 1), y = clamp(r, 0.0, 1.0) * float(N - 1);
  int x0 = min(int(x), N - 2), y0 = min(int(y), N - 2);
  float fx = x - float(x0), fy = y - float(y0);
  vec2 a = texelFetch(split_sum, ivec2(x0, y0), 0).xy, b = texelFetch(split_sum, ivec2(x0 + 1, y0), 0).xy;
  vec2 c = texelFetch(split_sum, ivec2(x0, y0 + 1), 0).xy, e = texelFetch(split_sum, ivec2(x0 + 1, y0 + 1), 0).xy;
  return mix(mix(a, b, fx), mix(c, e, fx), fy);
}
vec3 shade_pbr(vec3 base, vec3 n) {
  float metallic = metallic_factor, roughness = roughness_factor, ao = 1.0;
  vec3 emissive = emissive_factor;
  if (slots[1].on) { vec4 m = sample_slot(maps[1], 1); metallic *= m.b; roughness *= m.g; }
  if (slots[3].on) ao = 1.0 + occlusion_strength * (sample_slot(maps[3], 3).r - 1.0);
  if (slots[4].on) emissive *= sample_slot(maps[4], 4).rgb;
  vec3 v = normalize(eye - v_position);
  float r = clamp(roughness, 0.03, 1.0);
  vec3 direct = vec3(0.0);
  for (int i = 0; i < light_count; ++i) {
    vec3 l;
    vec3 E = irradiance_from(i, v_position, l);
    direct += brdf_cos(base, metallic, r, n, v, l) * E;
  }
  vec2 AB = split_sum_at(dot(n, v), r);
  vec3 f0 = mix(vec3(0.04), base, metallic);
  vec3 ambient = ao * (base * (1.0 - metallic) * env_radiance + (f0 * AB.x + AB.y) * env_radiance);
  return unlit ? base : direct + ambient + emissive;
}
void main() {
  vec4 base = base_factor * v_color;
  if (slots[0].on) base *= sample_slot(maps[0], 0);
  if (mask && base.a < cutoff) discard;
  float len = length(v_normal);
  vec3 n = len > 0.0 ? v_normal / len : v_normal;
  vec3 c;
  if (pbr) {
    if (slots[2].on) n = mapped_normal(n);
    if (!gl_FrontFacing) n = -n;
    c = shade_pbr(base.rgb, n);
  } else {
    if (!gl_FrontFacing) n = -n;
    c = base.rgb * (0.2 + 0.8 * max(dot(n, light), 0.0));
  }
  frag = vec4(min(c * exposure, vec3(65504.0)), 1.0);
}
)";

// A triangle covering the screen: the encoder runs once per display pixel.
const char* kFullscreenVertex = R"(#version 330 core
void main() {
  vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
  gl_Position = vec4(p, 0.0, 1.0);
}
)";

// Reading view v of the quilt (view 0 bottom-left, then left to right, then upward: GL's rows count
// upward like the quilt's). A quilt, as multi-view display software keeps its views, lets MSAA 0 draw
// straight into the tiles. Bilinear samples are clamped to the view's own tile, as pmr clamps to the view.
#define QUILT_GLSL                                                                                 \
  "uniform sampler2D views;\n"                                                                     \
  "uniform int quilt_columns;\n"                                                                   \
  "uniform ivec2 view_size;\n"                                                                     \
  "ivec2 tile_origin(int v) { return ivec2(v % quilt_columns, v / quilt_columns) * view_size; }\n" \
  "vec4 fetch(int v, ivec2 texel) { return texelFetch(views, tile_origin(v) + texel, 0); }\n"      \
  "vec4 bilinear(int v, vec2 p) {\n"                                                               \
  "  vec2 q = clamp(p * vec2(view_size), vec2(0.5), vec2(view_size) - 0.5);\n"                     \
  "  return texture(views, (vec2(tile_origin(v)) + q) / vec2(textureSize(views, 0)));\n"           \
  "}\n"

// DESIGN section 5 through pmr's exact tables (host/rig/display.cpp): subpixel k of display pixel
// (j, i) shows view v = a_mod_n - q_mod_n - (b < s) (+ N), sampled at its view pixel (px, py) (nearest)
// or at ((j + (k + 1/2) / 3) / W_d, (i + 1/2) / H_d) (bilinear). GL rows count upward, pmr's downward.
const char* kEncodeFragment = "#version 330 core\n" QUILT_GLSL R"(
uniform isampler2D columns;  // texel (j, 3 class + k): a_mod_n, b, px
uniform isampler2D rows;     // texel (i, 0): q_mod_n, s, py
uniform int view_count, reversed, cell_rows, use_bilinear;
uniform ivec2 display_size;
out vec4 frag;
vec4 subpixel(int j, int i, int k, int cls, ivec4 row) {
  ivec4 col = texelFetch(columns, ivec2(j, 3 * cls + k), 0);
  int v = col.x - row.x - (col.y < row.y ? 1 : 0);
  v = v < 0 ? v + view_count : v;
  v = reversed != 0 ? view_count - 1 - v : v;
  if (use_bilinear != 0) {
    vec2 p = vec2((float(j) + (float(k) + 0.5) / 3.0) / float(display_size.x), (float(i) + 0.5) / float(display_size.y));
    return bilinear(v, vec2(p.x, 1.0 - p.y));
  }
  return fetch(v, ivec2(col.z, view_size.y - 1 - row.z));
}
void main() {
  int j = int(gl_FragCoord.x), i = display_size.y - 1 - int(gl_FragCoord.y);
  int cls = cell_rows > 1 ? (display_size.y - 1 - i) % cell_rows : 0;
  ivec4 row = texelFetch(rows, ivec2(i, 0), 0);
  vec4 s0 = subpixel(j, i, 0, cls, row), s1 = subpixel(j, i, 1, cls, row), s2 = subpixel(j, i, 2, cls, row);
  frag = vec4(s0.r, s1.g, s2.b, (s0.a + s1.a + s2.a) / 3.0);
}
)";

// The same map as a typical interlacing shader computes it, in float arithmetic, without tables (a
// subpixel near a view boundary may pick the neighbouring view): t = (3j + k' - 3i tan_slant - offset) /
// lens_pitch, v = floor(frac(phase_sign t) N), sampled at the subpixel's own position.
const char* kEncodeFloatFragment = "#version 330 core\n" QUILT_GLSL R"(
uniform int view_count, reversed, use_bilinear, phase_sign, bgr;
uniform float tan_slant, offset, lens_pitch;
uniform ivec2 display_size;
out vec4 frag;
vec4 subpixel(int j, int i, int k) {
  float kk = float(bgr != 0 ? 2 - k : k);
  float t = (3.0 * float(j) + kk - 3.0 * float(i) * tan_slant - offset) / lens_pitch;
  int v = min(int(floor(fract(float(phase_sign) * t) * float(view_count))), view_count - 1);
  v = reversed != 0 ? view_count - 1 - v : v;
  vec2 p = vec2((float(j) + (float(k) + 0.5) / 3.0) / float(display_size.x), (float(i) + 0.5) / float(display_size.y));
  if (use_bilinear != 0) return bilinear(v, vec2(p.x, 1.0 - p.y));
  ivec2 texel = min(ivec2(p * vec2(view_size)), view_size - 1);
  return fetch(v, ivec2(texel.x, view_size.y - 1 - texel.y));
}
void main() {
  int j = int(gl_FragCoord.x), i = display_size.y - 1 - int(gl_FragCoord.y);
  vec4 s0 = subpixel(j, i, 0), s1 = subpixel(j, i, 1), s2 = subpixel(j, i, 2);
  frag = vec4(s0.r, s1.g, s2.b, (s0.a + s1.a + s2.a) / 3.0);
}
)";

// The scene in GL buffers: one vertex array, and per material one range of the index buffer.
struct Vertex {
  float position[3], normal[3], color[4], uv0[2], uv1[2], tangent[4];
};
struct Batch {
  int material = 0;
  GLsizei first = 0, count = 0;  // in indices
};
struct GlScene {
  GLuint vao = 0;
  std::vector<Batch> batches;
  std::vector<GLuint> textures;  // parallel to Scene::textures
  GLuint white = 0;              // bound where a material has no texture in a slot
  size_t triangles = 0;
};

Vertex make_vertex(const pmr::Scene& s, uint32_t v, const float* normal) {
  Vertex out{};
  for (int c = 0; c < 3; ++c) out.position[c] = s.positions[v][c], out.normal[c] = normal[c];
  std::memcpy(out.color, s.attributes[v].color, sizeof out.color);
  if (s.texcoords.size() > 0) out.uv0[0] = s.texcoords[0][v].x, out.uv0[1] = s.texcoords[0][v].y;
  if (s.texcoords.size() > 1) out.uv1[0] = s.texcoords[1][v].x, out.uv1[1] = s.texcoords[1][v].y;
  if (!s.tangents.empty()) std::memcpy(out.tangent, &s.tangents[v], sizeof out.tangent);
  return out;
}

// Indexed triangles grouped by material. A triangle without vertex normals gets three vertices of its
// own carrying its face normal (pmr shades it with the face normal).
void build_geometry(const pmr::Scene& s, std::vector<Vertex>& vertices, std::vector<uint32_t>& indices,
                    std::vector<Batch>& batches) {
  vertices.clear();
  for (size_t v = 0; v < s.positions.size(); ++v)
    vertices.push_back(make_vertex(s, uint32_t(v), s.attributes[v].normal));
  std::vector<std::vector<uint32_t>> per_material(s.materials.size());
  for (const PmrTriangle& t : s.triangles) {
    std::vector<uint32_t>& out = per_material.at(t.material);
    for (int k = 0; k < 3; ++k) {
      if (t.has_normals) {
        out.push_back(t.v[k]);
      } else {
        out.push_back(uint32_t(vertices.size()));
        vertices.push_back(make_vertex(s, t.v[k], t.face_normal));
      }
    }
  }
  indices.clear();
  batches.clear();
  for (size_t m = 0; m < per_material.size(); ++m) {
    if (per_material[m].empty()) continue;
    batches.push_back({int(m), GLsizei(indices.size()), GLsizei(per_material[m].size())});
    indices.insert(indices.end(), per_material[m].begin(), per_material[m].end());
  }
}

GLuint upload_geometry(const std::vector<Vertex>& vertices, const std::vector<uint32_t>& indices) {
  GLuint vao = 0, vbo = 0, ibo = 0;
  glGenVertexArrays(1, &vao);
  glBindVertexArray(vao);
  glGenBuffers(1, &vbo);
  glBindBuffer(GL_ARRAY_BUFFER, vbo);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(vertices.size() * sizeof(Vertex)), vertices.data(), GL_STATIC_DRAW);
  glGenBuffers(1, &ibo);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ibo);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(indices.size() * sizeof(uint32_t)), indices.data(), GL_STATIC_DRAW);
  const struct {
    GLint size;
    size_t offset;
  } attribs[] = {{3, offsetof(Vertex, position)}, {3, offsetof(Vertex, normal)}, {4, offsetof(Vertex, color)},
                 {2, offsetof(Vertex, uv0)},      {2, offsetof(Vertex, uv1)},    {4, offsetof(Vertex, tangent)}};
  for (GLuint a = 0; a < 6; ++a) {
    glEnableVertexAttribArray(a);
    glVertexAttribPointer(a, attribs[a].size, GL_FLOAT, GL_FALSE, sizeof(Vertex),
                          reinterpret_cast<const void*>(attribs[a].offset));
  }
  return vao;
}

// Colour maps as sRGB (decoded before filtering, as pmr decodes before its bilinear filter), data maps
// linear; mip-mapped trilinear unless mipmap is false. Rows as stored: glTF's (0, 0) is the image's
// top-left, which is texel row 0.
GLuint upload_texture(const pmr::SceneTexture& t, bool mipmap) {
  GLuint tex = 0;
  glGenTextures(1, &tex);
  glBindTexture(GL_TEXTURE_2D, tex);
  const bool srgb = (t.slots & ((1u << pmr::kSlotBaseColor) | (1u << pmr::kSlotEmissive))) != 0;
  glTexImage2D(GL_TEXTURE_2D, 0, srgb ? GL_SRGB8_ALPHA8 : GL_RGBA8, t.width, t.height, 0, GL_RGBA, GL_UNSIGNED_BYTE,
               t.rgba.data());
  if (mipmap) glGenerateMipmap(GL_TEXTURE_2D);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, mipmap ? GL_LINEAR_MIPMAP_LINEAR : GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, t.wrap_s);  // PMR_WRAP_* are the GL enums
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, t.wrap_t);
  return tex;
}

GlScene upload_scene(const pmr::Scene& s, bool mipmap) {
  GlScene g;
  std::vector<Vertex> vertices;
  std::vector<uint32_t> indices;
  build_geometry(s, vertices, indices, g.batches);
  g.vao = upload_geometry(vertices, indices);
  for (const pmr::SceneTexture& t : s.textures) g.textures.push_back(upload_texture(t, mipmap));
  pmr::SceneTexture white;
  white.width = white.height = 1;
  white.rgba = {255, 255, 255, 255};
  g.white = upload_texture(white, false);
  g.triangles = s.triangles.size();
  return g;
}

// pmr's split-sum table (A, B) of the uniform environment, read texel by texel as pmr reads it.
GLuint upload_split_sum() {
  const std::vector<float>& table = pmr::split_sum_table();
  GLuint tex = 0;
  glGenTextures(1, &tex);
  glBindTexture(GL_TEXTURE_2D, tex);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RG32F, PMR_SPLIT_SUM_N, PMR_SPLIT_SUM_N, 0, GL_RG, GL_FLOAT, table.data());
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  return tex;
}

// The render targets: the view atlas (a quilt of RGBA16F tiles: pmr's views are halves too), the
// framebuffer a view is drawn into, and the display image.
struct Targets {
  GLuint atlas = 0, draw_fbo = 0, resolve_fbo = 0, display_tex = 0, display_fbo = 0;
  GLuint columns = 0, rows = 0;
  int msaa = 0;
};

GLuint renderbuffer(GLenum format, int samples, int w, int h) {
  GLuint rb = 0;
  glGenRenderbuffers(1, &rb);
  glBindRenderbuffer(GL_RENDERBUFFER, rb);
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, format, w, h);
  return rb;
}

void check_framebuffer(const char* what) {
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
    throw std::runtime_error(std::string("the ") + what + " framebuffer is incomplete");
}

// With MSAA a view is drawn into view-sized multisampled renderbuffers and resolved into its quilt
// tile; without, it is drawn straight into its tile (viewport and scissor) over a quilt-sized depth
// buffer. Depth is float: pmr's is a float window depth.
void create_view_targets(const Frame& f, int msaa, Targets& t) {
  GLint max_size = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
  const int qw = f.quilt_columns * f.view_w, qh = f.quilt_rows * f.view_h;
  if (qw > max_size || qh > max_size)
    throw std::runtime_error("the views (a " + std::to_string(qw) + "x" + std::to_string(qh) +
                             " quilt) do not fit one texture of at most " + std::to_string(max_size));
  glGenTextures(1, &t.atlas);
  glBindTexture(GL_TEXTURE_2D, t.atlas);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA16F, qw, qh, 0, GL_RGBA, GL_HALF_FLOAT, nullptr);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);  // used by bilinear sampling only
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glGenFramebuffers(1, &t.draw_fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, t.draw_fbo);
  if (msaa > 0) {
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER,
                              renderbuffer(GL_DEPTH_COMPONENT32F, msaa, f.view_w, f.view_h));
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                              renderbuffer(GL_RGBA16F, msaa, f.view_w, f.view_h));
    check_framebuffer("multisampled view");
    glGenFramebuffers(1, &t.resolve_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, t.resolve_fbo);
  } else {
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER,
                              renderbuffer(GL_DEPTH_COMPONENT32F, 0, qw, qh));
  }
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, t.atlas, 0);
  check_framebuffer("view");
}

// pmr's encoder tables as integer textures (columns: one row per subpixel k and row class).
void create_encode_tables(const Frame& f, Targets& t) {
  const PmrEncodeParams p = pmr::make_encode_params(f.display, f.views, f.view_w, f.view_h);
  std::vector<PmrEncodeColumn> columns;
  std::vector<PmrEncodeRow> rows;
  pmr::make_encode_tables(f.display, p, columns, rows);
  const int w = f.display.width, h = f.display.height, classes = std::max(1, p.cell_rows);
  std::vector<int32_t> col_texels(size_t(w) * 3 * size_t(classes) * 4), row_texels(size_t(h) * 4);
  for (int c = 0; c < classes; ++c)
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < w; ++j) {
        const PmrEncodeColumn& e = columns[size_t(c) * 3 * size_t(w) + 3 * size_t(j) + size_t(k)];
        int32_t* texel = &col_texels[((size_t(c) * 3 + size_t(k)) * size_t(w) + size_t(j)) * 4];
        texel[0] = e.a_mod_n, texel[1] = e.b, texel[2] = e.px;
      }
  for (int i = 0; i < h; ++i)
    row_texels[size_t(i) * 4] = rows[i].q_mod_n, row_texels[size_t(i) * 4 + 1] = rows[i].s,
                           row_texels[size_t(i) * 4 + 2] = rows[i].py;
  glGenTextures(1, &t.columns);
  glBindTexture(GL_TEXTURE_2D, t.columns);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32I, w, 3 * classes, 0, GL_RGBA_INTEGER, GL_INT, col_texels.data());
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glGenTextures(1, &t.rows);
  glBindTexture(GL_TEXTURE_2D, t.rows);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32I, h, 1, 0, GL_RGBA_INTEGER, GL_INT, row_texels.data());
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
}

void create_display_target(const Frame& f, Targets& t) {
  glGenTextures(1, &t.display_tex);
  glBindTexture(GL_TEXTURE_2D, t.display_tex);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA16F, f.display.width, f.display.height, 0, GL_RGBA, GL_HALF_FLOAT, nullptr);
  glGenFramebuffers(1, &t.display_fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, t.display_fbo);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, t.display_tex, 0);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
    throw std::runtime_error("the display framebuffer is incomplete");
}

struct Programs {
  GLuint scene = 0, encode = 0;
  GLuint empty_vao = 0;  // core profile: the encoder's draw needs a vertex array, without attributes
};

// One texture slot: its texture on unit k (a white texel when absent: every sampler has a 2D texture),
// its texCoord set and KHR_texture_transform (u' = sx cos(r) u + sy sin(r) v + ox, v' = -sx sin(r) u
// + sy cos(r) v + oy).
void bind_slot(const GlScene& g, GLuint program, int k, const pmr::SceneTextureSlot& slot) {
  const std::string name = "slots[" + std::to_string(k) + "].";
  glActiveTexture(GLenum(GL_TEXTURE0 + k));
  glBindTexture(GL_TEXTURE_2D, slot.texture >= 0 ? g.textures.at(size_t(slot.texture)) : g.white);
  glUniform1i(glGetUniformLocation(program, (name + "on").c_str()), slot.texture >= 0);
  if (slot.texture < 0) return;
  if (slot.texcoord > 1) throw std::runtime_error("textures on TEXCOORD_2 and up are not implemented here");
  glUniform1i(glGetUniformLocation(program, (name + "set").c_str()), slot.texcoord);
  const float c = std::cos(slot.rotation), sn = std::sin(slot.rotation);
  const float sx = slot.scale[0], sy = slot.scale[1];
  glUniform3f(glGetUniformLocation(program, (name + "u").c_str()), sx * c, sy * sn, slot.offset[0]);
  glUniform3f(glGetUniformLocation(program, (name + "v").c_str()), -sx * sn, sy * c, slot.offset[1]);
}

// The maps the baseline's shader samples (maps[5]): the core metallic-roughness slots. It draws no
// material extension (transmission, clear coat, specular), so its scenes should have none.
constexpr int kGlMaps = pmr::kSlotEmissive + 1;

// One material's uniforms and state (DESIGN 4: MASK discards below the cutoff, BLEND is drawn opaque;
// single-sided materials are culled on back faces). Lambert reads the base colour slot alone.
void bind_material(const pmr::Scene& s, const GlScene& g, GLuint program, int m, bool pbr) {
  const PmrMaterial& mat = s.materials[size_t(m)];
  glUniform4fv(glGetUniformLocation(program, "base_factor"), 1, mat.base_color);
  glUniform1i(glGetUniformLocation(program, "mask"), mat.alpha_mode == PMR_ALPHA_MASK);
  glUniform1f(glGetUniformLocation(program, "cutoff"), mat.alpha_cutoff);
  if (mat.double_sided) glDisable(GL_CULL_FACE);
  else glEnable(GL_CULL_FACE);
  const pmr::SceneMaterialInputs in =
      size_t(m) < s.material_inputs.size() ? s.material_inputs[size_t(m)] : pmr::SceneMaterialInputs();
  for (int k = 0; k < kGlMaps; ++k)
    bind_slot(g, program, k, k == pmr::kSlotBaseColor || pbr ? in.slots[size_t(k)] : pmr::SceneTextureSlot());
  glActiveTexture(GL_TEXTURE0);
  if (!pbr) return;
  glUniform1f(glGetUniformLocation(program, "metallic_factor"), mat.metallic);
  glUniform1f(glGetUniformLocation(program, "roughness_factor"), mat.roughness);
  glUniform1f(glGetUniformLocation(program, "normal_scale"), mat.normal_scale);
  glUniform1f(glGetUniformLocation(program, "occlusion_strength"), mat.occlusion_strength);
  glUniform3fv(glGetUniformLocation(program, "emissive_factor"), 1, mat.emissive);
  glUniform1i(glGetUniformLocation(program, "unlit"), mat.unlit != 0);
}

// The frame's shading uniforms: Lambert's light, or pbr's lights, environment and split-sum table.
void set_shading_uniforms(const Frame& f, GLuint program, GLuint split_sum) {
  glUseProgram(program);
  for (int k = 0; k < kGlMaps; ++k)
    glUniform1i(glGetUniformLocation(program, ("maps[" + std::to_string(k) + "]").c_str()), k);
  glUniform1i(glGetUniformLocation(program, "split_sum"), kGlMaps);
  glActiveTexture(GL_TEXTURE0 + kGlMaps);
  glBindTexture(GL_TEXTURE_2D, split_sum);
  glActiveTexture(GL_TEXTURE0);
  glUniform1i(glGetUniformLocation(program, "pbr"), f.shading == "pbr");
  glUniform1f(glGetUniformLocation(program, "exposure"), f.exposure);
  glUniform3fv(glGetUniformLocation(program, "light"), 1, glm::value_ptr(f.light_world));
  glUniform1f(glGetUniformLocation(program, "env_radiance"), f.env_radiance);
  glUniform1i(glGetUniformLocation(program, "light_count"), int(f.lights.size()));
  for (size_t i = 0; i < f.lights.size(); ++i) {
    const pmr::SceneLight& l = f.lights[i];
    auto at = [&](const char* name) {
      return glGetUniformLocation(program, (std::string(name) + "[" + std::to_string(i) + "]").c_str());
    };
    glUniform1i(at("light_type"), l.type == pmr::SceneLightType::Point  ? 1
                                  : l.type == pmr::SceneLightType::Spot ? 2
                                                                        : 0);
    glUniform3f(at("light_color"), l.color[0] * l.intensity, l.color[1] * l.intensity, l.color[2] * l.intensity);
    glUniform3fv(at("light_position"), 1, glm::value_ptr(glm::vec3(l.position)));
    glUniform3fv(at("light_direction"), 1, glm::value_ptr(glm::vec3(l.direction)));
    glUniform1f(at("light_range"), l.range);
    glUniform1f(at("light_cos_inner"), std::cos(l.inner_cone));
    glUniform1f(at("light_cos_outer"), std::cos(l.outer_cone));
  }
}

// Pass 1: the N views, one pass each, each drawn into or resolved into its quilt tile.
void draw_views(const pmr::Scene& s, const GlScene& g, const Frame& f, const Programs& p, const Targets& t, int msaa) {
  glUseProgram(p.scene);
  glBindVertexArray(g.vao);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glClearColor(0.0f, 0.0f, 0.0f, 0.0f);
  const GLint clip = glGetUniformLocation(p.scene, "clip_from_world"), eye = glGetUniformLocation(p.scene, "eye");
  const bool pbr = f.shading == "pbr";
  if (msaa == 0) glEnable(GL_SCISSOR_TEST);  // the clear of one tile
  for (int v = 0; v < f.views; ++v) {
    const int x = v % f.quilt_columns * f.view_w, y = v / f.quilt_columns * f.view_h;
    glBindFramebuffer(GL_FRAMEBUFFER, t.draw_fbo);
    glViewport(msaa ? 0 : x, msaa ? 0 : y, f.view_w, f.view_h);
    glScissor(x, y, f.view_w, f.view_h);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glUniformMatrix4fv(clip, 1, GL_FALSE, glm::value_ptr(f.clip_from_world[size_t(v)]));
    glUniform3fv(eye, 1, glm::value_ptr(f.eyes[size_t(v)]));
    for (const Batch& b : g.batches) {
      bind_material(s, g, p.scene, b.material, pbr);
      glDrawElements(GL_TRIANGLES, b.count, GL_UNSIGNED_INT, reinterpret_cast<const void*>(size_t(b.first) * 4));
    }
    if (msaa == 0) continue;
    glBindFramebuffer(GL_READ_FRAMEBUFFER, t.draw_fbo);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, t.resolve_fbo);
    glBlitFramebuffer(0, 0, f.view_w, f.view_h, x, y, x + f.view_w, y + f.view_h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  }
  glDisable(GL_SCISSOR_TEST);
  glDisable(GL_CULL_FACE);
  glDisable(GL_DEPTH_TEST);
}

// Pass 2: the display encoding, one fragment per display pixel.
void encode_display(const Frame& f, const Programs& p, const Targets& t) {
  glUseProgram(p.encode);
  glBindVertexArray(p.empty_vao);
  glBindFramebuffer(GL_FRAMEBUFFER, t.display_fbo);
  glViewport(0, 0, f.display.width, f.display.height);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, t.atlas);
  glActiveTexture(GL_TEXTURE1);
  glBindTexture(GL_TEXTURE_2D, t.columns);
  glActiveTexture(GL_TEXTURE2);
  glBindTexture(GL_TEXTURE_2D, t.rows);
  glActiveTexture(GL_TEXTURE0);
  glDrawArrays(GL_TRIANGLES, 0, 3);
}

void set_encode_uniforms(const Frame& f, GLuint program) {
  glUseProgram(program);
  glUniform1i(glGetUniformLocation(program, "views"), 0);
  glUniform1i(glGetUniformLocation(program, "columns"), 1);
  glUniform1i(glGetUniformLocation(program, "rows"), 2);
  glUniform1i(glGetUniformLocation(program, "view_count"), f.views);
  glUniform1i(glGetUniformLocation(program, "reversed"), f.display.reversed);
  glUniform1i(glGetUniformLocation(program, "cell_rows"), f.display.cell_offsets.empty() ? 1 : f.display.cell_rows);
  glUniform1i(glGetUniformLocation(program, "use_bilinear"), f.display.bilinear);
  glUniform1i(glGetUniformLocation(program, "quilt_columns"), f.quilt_columns);
  glUniform2i(glGetUniformLocation(program, "display_size"), f.display.width, f.display.height);
  glUniform2i(glGetUniformLocation(program, "view_size"), f.view_w, f.view_h);
  // the float encoder's (the tables' shader has no such uniforms: these calls do nothing there)
  glUniform1i(glGetUniformLocation(program, "phase_sign"), f.display.phase_sign);
  glUniform1i(glGetUniformLocation(program, "bgr"), f.display.subpixel_bgr);
  glUniform1f(glGetUniformLocation(program, "tan_slant"), float(f.display.tan_slant.value()));
  glUniform1f(glGetUniformLocation(program, "offset"), float(f.display.offset.value()));
  glUniform1f(glGetUniformLocation(program, "lens_pitch"), float(f.display.lens_pitch.value()));
}

double now_ms() {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

struct FrameTimes {
  double views = 0, encode = 0, readback = 0, total = 0;
};

// One frame; glFinish closes each pass so its time is its own (llvmpipe runs passes asynchronously).
FrameTimes render_frame(const pmr::Scene& s, const GlScene& g, const Frame& f, const Programs& p, const Targets& t,
                        int msaa, std::vector<uint16_t>& display) {
  FrameTimes ft;
  const double t0 = now_ms();
  draw_views(s, g, f, p, t, msaa);
  glFinish();
  const double t1 = now_ms();
  encode_display(f, p, t);
  glFinish();
  const double t2 = now_ms();
  glBindFramebuffer(GL_READ_FRAMEBUFFER, t.display_fbo);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, f.display.width, f.display.height, GL_RGBA, GL_HALF_FLOAT, display.data());
  glFinish();
  const double t3 = now_ms();
  ft.views = t1 - t0, ft.encode = t2 - t1, ft.readback = t3 - t2, ft.total = t3 - t0;
  return ft;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// An EXR part of half RGBA from bottom-up GL rows (EXR rows run top-down).
void add_part(std::vector<Imf::Header>& headers, std::vector<std::vector<uint16_t>>& pixels, const std::string& name,
              const uint16_t* gl_rows, int w, int h) {
  Imf::Header hd(w, h);
  hd.setName(name);
  hd.setType(Imf::SCANLINEIMAGE);
  hd.compression() = Imf::ZIP_COMPRESSION;
  for (const char* c : {"R", "G", "B", "A"}) hd.channels().insert(c, Imf::Channel(Imf::HALF));
  headers.push_back(hd);
  std::vector<uint16_t> top_down(size_t(w) * size_t(h) * 4);
  for (int y = 0; y < h; ++y)
    std::memcpy(&top_down[size_t(y) * size_t(w) * 4], gl_rows + size_t(h - 1 - y) * size_t(w) * 4, size_t(w) * 8);
  pixels.push_back(std::move(top_down));
}

void write_parts(const std::string& path, const std::vector<Imf::Header>& headers,
                 std::vector<std::vector<uint16_t>>& pixels) {
  Imf::MultiPartOutputFile file(path.c_str(), headers.data(), int(headers.size()));
  for (size_t p = 0; p < headers.size(); ++p) {
    Imf::OutputPart part(file, int(p));
    const int w = headers[p].dataWindow().max.x + 1, h = headers[p].dataWindow().max.y + 1;
    Imf::FrameBuffer fb;
    const char* names[] = {"R", "G", "B", "A"};
    for (int c = 0; c < 4; ++c)
      fb.insert(names[c], Imf::Slice(Imf::HALF, reinterpret_cast<char*>(pixels[p].data() + c), 8, size_t(w) * 8));
    part.setFrameBuffer(fb);
    part.writePixels(h);
  }
}

// The encoded image (pmr's frame_NNNN.exr without the per-subpixel alphas) and the views (pmr's
// frame_NNNN.views.exr layout: one part view_NNN per view), for image comparisons with pmr's files.
void write_outputs(const Frame& f, const Targets& t, const std::vector<uint16_t>& display, const std::string& dir) {
  std::filesystem::create_directories(dir);
  std::vector<Imf::Header> headers;
  std::vector<std::vector<uint16_t>> pixels;
  add_part(headers, pixels, "encoded", display.data(), f.display.width, f.display.height);
  write_parts(dir + "/gl_encoded.exr", headers, pixels);
  std::vector<uint16_t> view(size_t(f.view_w) * size_t(f.view_h) * 4);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, t.msaa ? t.resolve_fbo : t.draw_fbo);  // the quilt
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  headers.clear(), pixels.clear();
  char name[32];
  for (int v = 0; v < f.views; ++v) {
    glReadPixels(v % f.quilt_columns * f.view_w, v / f.quilt_columns * f.view_h, f.view_w, f.view_h, GL_RGBA,
                 GL_HALF_FLOAT, view.data());
    std::snprintf(name, sizeof name, "view_%03d", v);
    add_part(headers, pixels, name, view.data(), f.view_w, f.view_h);
  }
  write_parts(dir + "/gl_views.exr", headers, pixels);
}

void print_setup(const Options& o, const Frame& f, const GlScene& g) {
  std::printf("renderer: %s (%s), LP_NUM_THREADS=%s\n", reinterpret_cast<const char*>(glGetString(GL_RENDERER)),
              reinterpret_cast<const char*>(glGetString(GL_VERSION)), std::getenv("LP_NUM_THREADS"));
  std::printf("scene: %s, %zu triangles, %zu batches, %zu textures (%s)\n", o.scene.c_str(), g.triangles,
              g.batches.size(), g.textures.size(), o.mipmap ? "mip-mapped" : "no mip-maps");
  std::printf("views: %d x %dx%d, MSAA %d; display %dx%d (%s); shading %s", f.views, f.view_w, f.view_h, o.msaa,
              f.display.width, f.display.height, f.display.bilinear ? "bilinear" : "nearest", f.shading.c_str());
  std::printf(" (sidecar: %s sampling, %d spp)\n", f.sampling.c_str(), f.samples);
  if (f.sampling != "view")
    std::printf("note: the sidecar's frame used %s sampling; this draws view sampling\n", f.sampling.c_str());
}

int run(const Options& o) {
  const Frame f = read_sidecar(o.sidecar);
  if (o.float_encoder && !f.display.cell_offsets.empty())
    throw std::runtime_error("--encoder float has no subpixel cells (display.cell_rows): use tables");
  const pmr::Scene scene = pmr::load_scene(o.scene);
  create_context();
  const GlScene g = upload_scene(scene, o.mipmap);
  Programs p{link(kSceneVertex, kSceneFragment),
             link(kFullscreenVertex, o.float_encoder ? kEncodeFloatFragment : kEncodeFragment), 0};
  glGenVertexArrays(1, &p.empty_vao);
  set_shading_uniforms(f, p.scene, upload_split_sum());
  set_encode_uniforms(f, p.encode);
  Targets t;
  t.msaa = o.msaa;
  create_view_targets(f, o.msaa, t);
  create_encode_tables(f, t);
  create_display_target(f, t);
  print_setup(o, f, g);
  std::vector<uint16_t> display(size_t(f.display.width) * size_t(f.display.height) * 4);
  std::vector<double> total, views, encode, readback;
  for (int frame = 0; frame <= o.frames; ++frame) {
    const FrameTimes ft = render_frame(scene, g, f, p, t, o.msaa, display);
    if (glGetError() != GL_NO_ERROR) throw std::runtime_error("OpenGL reported an error");
    if (frame == 0) continue;  // warm-up: shader variants compiled, memory touched
    total.push_back(ft.total), views.push_back(ft.views), encode.push_back(ft.encode), readback.push_back(ft.readback);
  }
  std::printf("median of %d frames: %.1f ms/frame (views %.1f, interlace %.1f, readback %.1f)\n", o.frames,
              median(total), median(views), median(encode), median(readback));
  // for tests/bench/gl_compare.sh
  std::printf("GL_MS_PER_FRAME %.3f %.3f %.3f %.3f\n", median(total), median(views), median(encode), median(readback));
  if (!o.out.empty()) write_outputs(f, t, display, o.out);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  try {
    o = parse_options(argc, argv);
  } catch (const std::exception& e) {
    if (*e.what()) std::fprintf(stderr, "pmr_gl_bench: %s\n", e.what());
    std::fprintf(stderr, "%s", kUsage);
    return 2;
  }
  try {
    return run(o);
  } catch (const NoContext& e) {
    std::fprintf(stderr, "pmr_gl_bench: %s\n", e.what());
    return kExitNoContext;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pmr_gl_bench: %s\n", e.what());
    return 1;
  }
}
