#include "cli/options.h"

#include <cerrno>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "pmr/error.h"

namespace pmr {

namespace {

double parse_double(const std::string& text, const std::string& opt) {
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || errno != 0 || !std::isfinite(v))
    throw Error("invalid " + opt + " '" + text + "': expected a number");
  return v;
}

}  // namespace

double parse_exposure(const std::string& text) {
  const double ev = parse_double(text, "--exposure");
  if (ev < -64.0 || ev > 64.0) throw Error("invalid --exposure '" + text + "': expected EV from -64 to 64");
  return ev;
}

double parse_environment_intensity(const std::string& text) {
  const double x = parse_double(text, "--environment-intensity");
  if (x < 0.0 || x > 1e6) throw Error("invalid --environment-intensity '" + text + "': expected 0 to 1e6");
  return x;
}

double parse_environment_rotation(const std::string& text) {
  return parse_double(text, "--environment-rotation");  // any finite angle
}

void check_environment_options(const std::string& file, bool rotation_given, Shading shading,
                               std::vector<std::string>& warnings) {
  if (!file.empty() && shading != Shading::Pbr)
    throw Error("--environment lights the pbr model only: add --shading pbr");
  if (file.empty() && rotation_given)
    warnings.push_back("--environment-rotation turns an environment image: without --environment it does nothing");
}

namespace {

int parse_int(const std::string& text, const std::string& opt, int lo, int hi) {
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || errno != 0 || v < lo || v > hi)
    throw Error("invalid " + opt + " '" + text + "': expected an integer in " + std::to_string(lo) + ".." +
                std::to_string(hi));
  return int(v);
}

// "WxH" or "XxYxV".
std::vector<int> parse_dims(const std::string& text, const std::string& opt, size_t count, int hi) {
  std::vector<int> out;
  std::stringstream ss(text);
  std::string part;
  while (std::getline(ss, part, 'x')) out.push_back(parse_int(part, opt, 1, hi));
  if (out.size() != count || text.back() == 'x')
    throw Error("invalid " + opt + " '" + text + "': expected " + (count == 2 ? "WxH" : "XxYxV"));
  return out;
}

}  // namespace

namespace {

// The rig a Looking Glass panel's serial prefix recommends (the preset of that model, whose default
// sampling `subpixel` receives), or 48 views of the panel's aspect for an unknown one.
RigConfig rig_for_serial(const LookingGlassCalibration& c, std::string& quilt, bool& subpixel) {
  const std::pair<const char*, const char*> models[] = {{"LKG-P", "lg-portrait"}, {"LKG-E", "lg-go"},
                                                        {"LKG-J", "lg-16"},       {"LKG-H", "lg-16-portrait"},
                                                        {"LKG-L", "lg-32"},       {"LKG-K", "lg-32-portrait"},
                                                        {"LKG-A", "lg-16-gen2"},  {"LKG-B", "lg-32-gen2"}};
  for (const auto& [prefix, preset] : models)
    if (c.serial.rfind(prefix, 0) == 0) {
      const DisplayPreset& p = find_display_preset(preset);
      quilt = p.quilt;
      subpixel = p.subpixel_sampling;
      RigConfig r = p.rig;
      r.cone_deg = c.view_cone;
      return r;
    }
  RigConfig r;
  r.views = 48;
  r.view_h = 560;
  r.view_w = std::max(1, int(std::lround(560.0 * c.screen_w / c.screen_h)));
  r.cone_deg = c.view_cone;
  return r;
}

// --preset and --display-config set the defaults that every other option then overrides.
void apply_display_source(RenderOptions& o, const std::vector<std::string>& args) {
  for (size_t i = 0; i + 1 < args.size(); ++i)  // the calibration file is read under the file-bytes budget
    if (args[i] == "--limit") as_usage([&] { parse_limits(args[i + 1], o.input_limits); });
  for (size_t i = 0; i + 1 < args.size(); ++i) {
    if (args[i] == "--preset") {
      if (args[i + 1] == "help") {
        o.preset_help = true;
        return;
      }
      const DisplayPreset& p = as_usage([&]() -> const DisplayPreset& { return find_display_preset(args[i + 1]); });
      o.display = p.display;
      o.offset_given = p.name != "paper-8k";  // a panel's offset comes from its calibration
      o.rig = p.rig;
      o.rig.angular_spacing = p.name != "paper-8k";  // Looking Glass software spaces its cameras angularly
      o.pipeline.sampling = p.subpixel_sampling ? Sampling::Subpixel : Sampling::View;
      o.display_source = "preset " + p.name;
      o.quilt_preview_opaque = p.name != "paper-8k";  // Looking Glass tools show quilts opaque
    } else if (args[i] == "--display-config") {
      o.calibration = read_looking_glass_calibration(args[i + 1], &o.option_warnings, o.input_limits.file_bytes);
      o.has_calibration = true;
      o.display = display_from_calibration(o.calibration);
      o.offset_given = true;  // the calibration's center decides it
      std::string quilt;
      bool subpixel = false;
      o.rig = rig_for_serial(o.calibration, quilt, subpixel);
      o.rig.angular_spacing = true;
      o.pipeline.sampling = subpixel ? Sampling::Subpixel : Sampling::View;
      o.display_source = "calibration " + args[i + 1];
      o.quilt_preview_opaque = true;
    }
  }
  int sources = 0;
  for (const std::string& a : args) sources += a == "--preset" || a == "--display-config";
  if (sources > 1) throw UsageError("give one of --preset and --display-config, once");
}

// The options after apply_display_source: anything they throw is a usage error (they read no file).
void parse_arguments(RenderOptions& o, const std::vector<std::string>& args) {
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= args.size()) throw Error("option " + a + " needs a value (see pmr render --help)");
      return args[++i];
    };
    if (a == "-h" || a == "--help") o.help = true;
    else if (a == "--out" || a == "-o") o.out_dir = value();
    else if (a == "--preset" || a == "--display-config") value();  // applied first (apply_display_source)
    else if (a == "--views") o.rig.views = parse_int(value(), a, 1, 4096);
    else if (a == "--view-size") {
      const auto d = parse_dims(value(), a, 2, PMR_MAX_RASTER);
      o.rig.view_w = d[0], o.rig.view_h = d[1];
    } else if (a == "--display") {
      const auto d = parse_dims(value(), a, 2, 16384);
      o.display.width = d[0], o.display.height = d[1];
    } else if (a == "--display-size") {
      const std::string v = value();
      const auto x = v.find('x');
      if (x == std::string::npos) throw Error("invalid --display-size '" + v + "': expected WxH in cm");
      o.display.size_w_cm = parse_double(v.substr(0, x), a);
      o.display.size_h_cm = parse_double(v.substr(x + 1), a);
    } else if (a == "--viewing-distance") o.display.viewing_distance_cm = parse_double(value(), a);
    else if (a == "--cone") {
      const std::string v = value();
      o.rig.cone_deg = parse_double(v, a);
      if (!(o.rig.cone_deg > 0.0 && o.rig.cone_deg < 180.0)) throw Error("invalid --cone '" + v + "': expected degrees in (0, 180)");
    }
    else if (a == "--yfov") {
      const std::string v = value();
      o.rig.yfov_deg = parse_double(v, a);
      if (!(o.rig.yfov_deg > 0.0 && o.rig.yfov_deg < 180.0))  // 0 would silently mean "the display's default"
        throw Error("invalid --yfov '" + v + "': expected degrees in (0, 180)");
    }
    else if (a == "--lens-pitch") {
      const std::string v = value();
      o.display.lens_pitch = parse_rational(v, "--lens-pitch");
      if (o.display.lens_pitch.num <= 0) throw Error("invalid --lens-pitch '" + v + "': must be positive");
    }
    else if (a == "--tan-slant") o.display.tan_slant = parse_rational(value(), "--tan-slant");
    else if (a == "--offset") {
      o.display.offset = parse_rational(value(), "--offset");
      o.offset_given = true;
    } else if (a == "--reverse-views") o.display.reversed = true;
    else if (a == "--bilinear") o.display.bilinear = true;
    else if (a == "--blend-views") o.display.blend_views = true;
    else if (a == "--tile") {
      const auto d = parse_dims(value(), a, 3, 64);
      o.pipeline.tile_x = d[0], o.pipeline.tile_y = d[1], o.pipeline.tile_v = d[2];
    } else if (a == "--camera") o.rig.camera = parse_int(value(), a, 0, 1 << 30);
    else if (a == "--write") {
      o.write_encoded = o.write_views = o.write_quilt = o.write_depth = false;
      std::stringstream ss(value());
      std::string w;
      while (std::getline(ss, w, ',')) {
        if (w == "encoded") o.write_encoded = true;
        else if (w == "views") o.write_views = true;
        else if (w == "quilt") o.write_quilt = true;
        else if (w == "depth") o.write_depth = true;
        else throw Error("invalid --write '" + w + "': expected a list of encoded, views, quilt, depth");
      }
      if (!o.write_encoded && !o.write_views && !o.write_quilt)
        throw Error("invalid --write: nothing to write (depth is a channel of views or quilt)");
      if (o.write_depth && !o.write_views && !o.write_quilt)
        throw Error("invalid --write: depth is a channel of the views or quilt EXR: add views or quilt");
    } else if (a == "--compression") o.compression = value();
    else if (a == "--quilt") o.quilt = value();
    else if (a == "--preview") o.preview = true;
    else if (a == "--frame" || a == "--frames") o.frames = value();
    else if (a == "--fps") {
      o.fps = parse_double(value(), a);
      if (!(o.fps > 0.0) || o.fps > 10000.0) throw Error("invalid --fps: must be in (0, 10000]");
    } else if (a == "--animation") {
      o.animation = value();
      if (o.animation.empty()) throw Error("invalid --animation '': expected a name, an index, all or none");
    } else if (a == "--name") {
      o.name = value();
      check_name_pattern(o.name);
    } else if (a == "--turntable") {
      const std::string v = value();
      const auto colon = v.find(':');
      if (colon == std::string::npos) throw Error("invalid --turntable '" + v + "': expected DEG:FRAMES, e.g. 360:96");
      o.turntable = true;
      o.turntable_deg = parse_double(v.substr(0, colon), a);
      o.turntable_frames = parse_int(v.substr(colon + 1), a, 1, 1 << 30);
    } else if (a == "--shard") o.shard = value();
    else if (a == "--shard-count") o.shard_count = parse_int(value(), a, 1, 1 << 30);
    else if (a == "--shard-first") o.shard_first = parse_int(value(), a, 0, 1 << 30);
    else if (a == "--resume") o.resume = true;
    else if (a == "--overwrite") o.overwrite = true;
    else if (a == "--quiet" || a == "-q") o.quiet = true;
    else if (a == "--verbose" || a == "-v") o.verbose = true;
    else if (a == "--method") o.pipeline.method = parse_method(value()), o.method_given = true;
    else if (a == "--sampling") o.pipeline.sampling = parse_sampling(value()), o.sampling_given = true;
    else if (a == "--shading") o.pipeline.shading = parse_shading(value());
    else if (a == "--exposure") o.pipeline.exposure_ev = parse_exposure(value());
    else if (a == "--environment-intensity") o.pipeline.environment_intensity = parse_environment_intensity(value());
    else if (a == "--environment") {
      o.environment_file = value();
      if (o.environment_file.empty()) throw Error("invalid --environment '': expected a .hdr or .exr file");
    } else if (a == "--environment-rotation") {
      o.environment_rotation_deg = parse_environment_rotation(value());
      o.environment_rotation_given = true;
    }
    else if (a == "--zoom") {
      o.rig.zoom = parse_double(value(), a);
      if (!(o.rig.zoom >= 0.001 && o.rig.zoom <= 1000.0)) throw Error("invalid --zoom: expected a factor from 0.001 to 1000");
      o.zoom_given = true;
    }
    else if (a == "--camera-spacing") {
      const std::string v = value();
      if (v != "linear" && v != "angular") throw Error("invalid --camera-spacing '" + v + "': expected linear or angular");
      o.rig.angular_spacing = v == "angular";
    }
    else if (a == "--limit") parse_limits(value(), o.input_limits);
    else if (a == "--allow-outside-scene-folder") o.input_limits.allow_outside_scene_folder = true;
    else if (a == "--background") o.background = parse_background(value());
    else if (!a.empty() && a[0] == '-') throw Error("unknown option " + a + " (see pmr render --help)");
    else if (o.scene.empty()) o.scene = a;
    else throw Error("more than one scene given ('" + o.scene + "' and '" + a + "')");
  }
  if (o.zoom_given && o.rig.camera >= 0)
    throw Error("--zoom scales the framing of the scene's bounding sphere; a glTF camera (--camera) sets its own: "
                "give one of them");
}

}  // namespace

RenderOptions parse_render_options(const std::vector<std::string>& args) {
  RenderOptions o;
  apply_display_source(o, args);  // a bad --display-config file is bad input (exit 1), not a usage error
  as_usage([&] { parse_arguments(o, args); });
  return o;
}


namespace {

void finalize_options(RenderOptions& o) {
  if (o.display.blend_views && o.display.bilinear) throw UsageError("--blend-views and --bilinear cannot be combined");
  check_environment_options(o.environment_file, o.environment_rotation_given, o.pipeline.shading, o.option_warnings);
  if (o.pipeline.sampling == Sampling::Subpixel && !o.sampling_given) {
    // the preset's default: options that need the views rendered on their grids take precedence
    const std::string needs_views = o.pipeline.method != Method::Pmr ? "--method " + std::string(to_string(o.pipeline.method))
                                    : o.display.bilinear             ? "--bilinear"
                                    : o.display.blend_views          ? "--blend-views"
                                                                     : "";
    if (!needs_views.empty()) {
      o.pipeline.sampling = Sampling::View;
      o.option_warnings.push_back(needs_views + " samples the rendered views: --sampling view instead of the "
                                  "display's default, subpixel");
    } else if (!o.write_encoded) {
      o.pipeline.sampling = Sampling::View;  // no encoded image: nothing to sample by subpixel
    }
  }
  if (o.pipeline.sampling == Sampling::Subpixel) {
    check_subpixel_sampling(o.pipeline.method, o.display);  // pmr unless --method says otherwise
    if (!o.write_encoded) {  // the views are rendered on their grids in either case
      o.pipeline.sampling = Sampling::View;
      o.option_warnings.push_back("--sampling subpixel samples the encoded image, which --write does not ask for: "
                                  "ignored");
    }
  }
  if (!o.offset_given) {
    o.display.offset = default_offset(o.display.lens_pitch, o.rig.views);
  }
}

}  // namespace

void finalize_render_options(RenderOptions& o) {
  as_usage([&] { finalize_options(o); });  // combinations of options
}

std::string main_help() {
  return "pmr - multi-view light-field renderer (parallel multi-view polygon rasterization on OpenCL)\n"
         "\n"
         "usage:\n"
         "  pmr render [SCENE.gltf|SCENE.glb] [options]   render N views and the encoded display image\n"
         "  pmr bench [SCENE] [options]                  performance sweeps over view count and method\n"
         "  pmr quality [SCENE] [options]                sampling error against a 4x finer reference\n"
         "  pmr info                                     list OpenCL platforms and devices\n"
         "  pmr info SCENE                               what a scene holds (cameras, animations, ...)\n"
         "  pmr verify DIR --frames LIST                 which frames of a sequence are missing or broken\n"
         "  pmr --version                                the program version (as sidecars record it)\n"
         "  pmr --help | pmr render --help\n"
         "\n"
         "exit status: 0 success; 1 bad input, runtime error or out of memory; 2 usage error (unknown option,\n"
         "bad option value); 3 internal error; 128 + N when stopped by signal N (130 for Ctrl-C)\n";
}

std::string render_help() {
  return "usage: pmr render [SCENE] [options]\n"
         "Renders SCENE (glTF 2.0, .gltf or .glb; default: the bundled data/default_scene.glb) as N views\n"
         "and interlaces them into the display's subpixel image. Defaults are the preset paper-8k:\n"
         "96 views of 1024x512, a 7680x4320 display of 166x93 cm seen from 200 cm, 80 degree view cone.\n"
         "\n"
         "output:\n"
         "  --out DIR, -o DIR      output folder (created if missing; default: out)\n"
         "  --write LIST           any of encoded, views, quilt, depth (default: encoded). DIR/frame_NNNN.exr is\n"
         "                         the encoded image (half RGBA), DIR/frame_NNNN.views.exr one part per view,\n"
         "                         DIR/frame_NNNN_qsCxRaA.exr the views as a Looking Glass quilt (view 0 bottom\n"
         "                         left), depth a float Z channel (view-space depth, +inf where empty) in the\n"
         "                         views and quilt files; DIR/frame_NNNN.json (rig, display, every view's\n"
         "                         matrices) is always written\n"
         "  --quilt CxR            quilt layout in tiles (default: the most square layout, e.g. 8x6 for 48)\n"
         "  --preview              also 8-bit sRGB PNGs: the encoded image, the center view (N / 2; stretched to\n"
         "                         square pixels, as a view's pixels span the display's aspect) and the quilt\n"
         "                         (tiles as rendered; their pixel aspect in the PNG's pHYs chunk)\n"
         "  --name PATTERN         file stem (default frame_%04d); the frame number as %d, zero-padded %0Nd or\n"
         "                         Blender's #### (N '#': N digits), %% for a percent sign; without a frame\n"
         "                         number the stem of a single frame as given (--name duck: duck.exr)\n"
         "  --compression C        EXR compression: none, zip, zip-fast (ZIP through ISA-L's igzip alone: a\n"
         "                         third of zip's writer CPU, 10% larger files; any reader opens it), piz, rle\n"
         "                         (default zip)\n"
         "sequences (an animated glTF plays; frame f samples time f / fps; before the animation's first key\n"
         "and after its last a frame holds the first or last pose, as glTF clamps):\n"
         "  --frames LIST          frames to render: N, A:B (inclusive), A:B:STEP, a comma list of these\n"
         "                         (0:99,120,130:140), or all (default 0). all = the frames whose times lie\n"
         "                         inside the animation's keys, ceil(start x fps) to floor(end x fps); with\n"
         "                         --turntable one turn, 0 to FRAMES-1, however long the animation; frame 0\n"
         "                         for a still scene. Frames outside the keys get a warning, except all\n"
         "  --fps F                frames per second (default 24)\n"
         "  --animation A          NAME, INDEX, all (every animation at once) or none (the rest pose);\n"
         "                         default: the first one\n"
         "  --turntable DEG:FRAMES turn the scene DEG degrees every FRAMES frames about the vertical axis\n"
         "                         through its framing center (360:96 loops every 96 frames)\n"
         "  --resume               skip frames whose files are all present; refuse a changed configuration\n"
         "  --overwrite            render even though the folder keeps frames of another configuration\n"
         "                         outside --frames (a warning counts them; without it the run refuses);\n"
         "                         with --resume: also re-render listed frames of another configuration\n"
         "  --quiet, -q            print only errors and warnings\n"
         "  --shard K/N|auto       render only task K's share of the frames (interleaved: positions K, K+N,\n"
         "                         ...); auto reads a Slurm, Kubernetes, AWS Batch, PBS, SGE or LSF array index\n"
         "                         (--shard-count N where the environment lacks the count, --shard-first F\n"
         "                         for PBS arrays not starting at 0); see docs/farm/README.md\n"
         "rig:\n"
         "  --preset NAME          a display: paper-8k (default), lg-portrait, lg-go, lg-16, lg-32, ...\n"
         "                         (--preset help lists them); other options override its values\n"
         "  --display-config F     a Looking Glass panel's own calibration file (visual.json): display,\n"
         "                         encoder and the model's recommended views (docs/DISPLAYS.md)\n"
         "  --views N              number of views (default 96)\n"
         "  --view-size WxH        view raster in pixels (default 1024x512; each side <= 8192)\n"
         "  --cone DEG             view cone (default 80)\n"
         "  --yfov DEG             vertical field of view (default from the display: 2 atan(46.5 / 200))\n"
         "  --camera-spacing S     linear (PMR's, default for paper-8k) or angular (Looking Glass: D tan(cone\n"
         "                         ((i + 1/2) / N - 1/2)), default for the Looking Glass presets; each\n"
         "                         angular camera moves onto a fine fixed-point grid (docs/DESIGN.md)\n"
         "  --camera K             use the scene's glTF camera K (pose and field of view) instead of framing\n"
         "                         the scene's bounding sphere\n"
         "  --background R,G,B[,A] a linear colour behind the encoded image, views, quilt and previews (default\n"
         "                         transparent black; A defaults to 1). The encoded image is composited per\n"
         "                         subpixel; its PNG preview is always opaque (over black). With a Looking Glass\n"
         "                         preset or --display-config the quilt PNG is opaque black by default\n"
         "  --zoom F               the scene appears F times larger (default 1: its bounding sphere fits the\n"
         "                         view's height and width); the camera moves closer, the zero-parallax plane\n"
         "                         stays through the sphere's center. Not with --camera\n"
         "display:\n"
         "  --display WxH          display image in pixels (default 7680x4320)\n"
         "  --display-size WxH     physical size in cm (default 166x93; sets the aspect A)\n"
         "  --viewing-distance CM  (default 200)\n"
         "  --lens-pitch L         lens pitch in subpixels (default 16)\n"
         "  --tan-slant T          tangent of the lens slant (default 1/18)\n"
         "  --offset O             subpixel offset (default -L/(2N) = -1/12)\n"
         "                         (L, T, O accept decimals or fractions like 1/18; evaluated exactly)\n"
         "  --reverse-views        use view N-1-v instead of v\n"
         "  --bilinear             sample views bilinearly (default nearest)\n"
         "  --blend-views          blend the two nearest views by the lens phase, as Looking Glass's\n"
         "                         webxr shader does by default (default: one view per subpixel)\n"
         "pipeline:\n"
         "  --tile XxYxV           3D tile of the tile/fine raster, voxels over x, y, view (default 16x2x16)\n"
         "  --method M             pmr (default), multipass (one conventional pass per view) or duplicate\n"
         "                         (every triangle copied per view into a 2D-tiled view atlas)\n"
         "  --sampling S           view (default): the views rendered on their grids, each subpixel reading\n"
         "                         its view's nearest pixel; subpixel: every display subpixel rasterized at\n"
         "                         its own sample in its own view (docs/SAMPLING.md; the default of the\n"
         "                         presets listed there, which --bilinear, --blend-views or a --method\n"
         "                         other than pmr turn back to view sampling with a notice)\n"
         "shading (docs/SHADING.md):\n"
         "  --shading S            pbr (default): glTF metallic-roughness with every material map, seen from\n"
         "                         each view's own camera, so highlights move across the views; lit by the\n"
         "                         file's KHR_lights_punctual lights (moving with their nodes; without any,\n"
         "                         a default directional light) and a uniform environment or --environment;\n"
         "                         lambert: base colour x (0.2 + 0.8 max(0, n.l)), the same in every view,\n"
         "                         one fixed light (faster)\n"
         "  --exposure EV          the colour times 2^EV, either model (default 0)\n"
         "  --environment FILE     pbr: light with an equirectangular image of linear radiance (.hdr or .exr,\n"
         "                         path relative to the current folder) instead of the uniform environment\n"
         "                         and the default light (the file's lights stay); -Z is the image's middle\n"
         "                         column, +Y its top row; prefiltered once per run (1-2.5 s for 1024x512).\n"
         "                         Needs --shading pbr\n"
         "  --environment-rotation DEG  pbr: turn the image DEG degrees counter-clockwise seen from above\n"
         "                         (+X moves toward -Z; default 0)\n"
         "  --environment-intensity X  pbr: scales the environment, the image or the uniform one of radiance\n"
         "                         0.2 (0 turns it off; default 1)\n"
         "  --verbose, -v          per-stage device times and queue sizes\n"
         "untrusted input (docs/SECURITY.md):\n"
         "  --allow-outside-scene-folder  read files the scene names outside its folder (by default a\n"
         "                         buffer or image that resolves outside it is an error); recorded in the sidecar\n"
         "  --limit KEY=VALUE[,KEY=VALUE...]  raise or lower a budget (VALUE an integer, K/M/G/T = x1024^n):\n" +
         limit_help() +
         "Environment: PMR_DEVICE=substring selects the OpenCL device by name (default: first CPU device).\n"
         "Docs in the source tree: README.md, docs/DESIGN.md (rig, framing, encoder, files), docs/SHADING.md.\n";
}

}  // namespace pmr
