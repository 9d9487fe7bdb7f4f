#include "renders/scene_renderer.h"

#include <GL/osmesa.h>
#include <dlfcn.h>
#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <string>

#include "common/check.h"
#include "sim/obstacles.h"
#include "sim/scene_model.h"
#include "sim/simulator.h"

namespace mjslam::renders {

namespace {

// Height of the camera above the floor, metres; the frustum is narrow.
constexpr double kCameraHeightM = 200.0;
// Heights of the drawn layers, metres: paths on the floor under the robot;
// map, laser hits and ellipses above the walls (1 m) and the robot.
constexpr double kFloorLayerZ = 0.01;
constexpr double kMapLayerZ = 1.10;
constexpr double kHitLayerZ = 1.12;
constexpr double kEllipseLayerZ = 1.15;
// Room for the drawn geoms beyond the model's own.
constexpr int kMaxGeoms = 20000;
// Right-hand strip for the legend, pixels at font scale 100; no legend on
// images narrower than kMinWidthForLegend.
constexpr int kLegendWidth = 150;
constexpr int kMinWidthForLegend = 400;
constexpr float kWallGrey = 0.30f;
constexpr float kFloorGrey = 0.88f;

// OSMesa's entry points, loaded with dlopen on the first render rather than
// linked: libOSMesa pulls in LLVM, whose relocations cost every process about
// 0.1 s of CPU at start-up, rendering or not (docs/results.md, "Simulation
// cost"). RTLD_GLOBAL makes its OpenGL symbols visible to MuJoCo's loader,
// which looks them up in the process.
struct OsMesaApi {
  decltype(&OSMesaCreateContextExt) create_context_ext = nullptr;
  decltype(&OSMesaMakeCurrent) make_current = nullptr;
  decltype(&OSMesaGetCurrentContext) get_current_context = nullptr;
  decltype(&OSMesaDestroyContext) destroy_context = nullptr;
};

constexpr const char* kOsMesaLibrary = "libOSMesa.so.8";

// Loads the library once per process (never unloaded); std::runtime_error
// naming the library and the missing symbol when it cannot.
const OsMesaApi& LoadOsMesa() {
  static OsMesaApi api;
  static std::string problem;
  static std::once_flag once;
  std::call_once(once, [] {
    void* library = dlopen(kOsMesaLibrary, RTLD_NOW | RTLD_GLOBAL);
    if (library == nullptr) {
      const char* why = dlerror();
      problem = std::string("OSMesa: cannot load ") + kOsMesaLibrary + ": " + (why ? why : "?");
      return;
    }
    auto find = [&](const char* name) {
      void* symbol = dlsym(library, name);
      if (symbol == nullptr && problem.empty()) {
        problem = std::string("OSMesa: ") + kOsMesaLibrary + " has no " + name;
      }
      return symbol;
    };
    api.create_context_ext =
        reinterpret_cast<decltype(api.create_context_ext)>(find("OSMesaCreateContextExt"));
    api.make_current = reinterpret_cast<decltype(api.make_current)>(find("OSMesaMakeCurrent"));
    api.get_current_context =
        reinterpret_cast<decltype(api.get_current_context)>(find("OSMesaGetCurrentContext"));
    api.destroy_context =
        reinterpret_cast<decltype(api.destroy_context)>(find("OSMesaDestroyContext"));
  });
  if (!problem.empty()) throw std::runtime_error(problem);
  return api;
}

// One line of the legend: a swatch and its name.
struct LegendEntry {
  std::string text;
  Rgb color;
};

}  // namespace

struct SceneRenderer::Impl {
  int width = 0;
  int height = 0;
  int fontscale = mjFONTSCALE_100;
  int legend_width = 0;
  double control_point_offset_m = 0.0;
  std::vector<double> rest_qpos;

  // The renderer's copy of the scene's model (its colours and visual
  // options are changed) and the state drawn.
  sim::internal::ModelPtr model;
  sim::internal::DataPtr data;
  mjModel* m = nullptr;
  mjData* d = nullptr;
  mjvScene scn;
  mjvCamera cam;
  mjvOption opt;
  mjrContext con;
  OSMesaContext gl = nullptr;
  std::vector<unsigned char> gl_buffer;
  std::vector<unsigned char> readback;

  // The floor rectangle shown in the scene viewport: centre and half sizes.
  Eigen::Vector2d view_center = Eigen::Vector2d::Zero();
  double half_width_m = 1.0;
  double half_height_m = 1.0;

  Impl() {
    // Defaults first, so that the destructor may free them whatever stage
    // the construction reached.
    mjv_defaultScene(&scn);
    mjr_defaultContext(&con);
  }

  ~Impl() {
    mjr_freeContext(&con);
    mjv_freeScene(&scn);
    data.reset();
    model.reset();
    if (gl != nullptr) {
      // Release the context before destroying it: Mesa keeps a current
      // context's state alive (a leak LeakSanitizer reports per process).
      // (gl is set only once LoadOsMesa succeeded.)
      const OsMesaApi& osmesa = LoadOsMesa();
      if (osmesa.get_current_context() == gl) {
        osmesa.make_current(nullptr, nullptr, GL_UNSIGNED_BYTE, 0, 0);
      }
      osmesa.destroy_context(gl);
    }
  }

  mjrRect SceneViewport() const { return {0, 0, width - legend_width, height}; }

  // The point drawn at height z that appears where the floor point p does.
  void Lift(const Eigen::Vector2d& p, double z, mjtNum out[3]) const {
    const double k = (kCameraHeightM - z) / kCameraHeightM;
    out[0] = view_center.x() + (p.x() - view_center.x()) * k;
    out[1] = view_center.y() + (p.y() - view_center.y()) * k;
    out[2] = z;
  }

  mjvGeom* NewGeom() {
    if (scn.ngeom >= scn.maxgeom) return nullptr;  // silently full: drawing is best effort
    return scn.geoms + scn.ngeom++;
  }

  // A flat bar from a to b, `width_px` pixels wide, at height z: a box,
  // since OpenGL line widths are not under MuJoCo's control.
  void AddSegment(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double z, const Rgb& color,
                  double width_px) {
    mjvGeom* g = NewGeom();
    if (g == nullptr) return;
    const float rgba[4] = {color[0], color[1], color[2], 1.0f};
    mjtNum pa[3], pb[3];
    Lift(a, z, pa);
    Lift(b, z, pb);
    const double dx = pb[0] - pa[0], dy = pb[1] - pa[1];
    const double half_width = 0.5 * width_px * PixelM();
    // Overlap the joints of a polyline by half a width at each end.
    const mjtNum size[3] = {0.5 * std::hypot(dx, dy) + half_width, half_width, 0.002};
    const mjtNum pos[3] = {0.5 * (pa[0] + pb[0]), 0.5 * (pa[1] + pb[1]), z};
    const double angle = std::atan2(dy, dx);
    const double c = std::cos(angle), s = std::sin(angle);
    const mjtNum mat[9] = {c, -s, 0, s, c, 0, 0, 0, 1};
    mjv_initGeom(g, mjGEOM_BOX, size, pos, mat, rgba);
    g->category = mjCAT_DECOR;
    g->emission = 0.0f;
    g->specular = 0.0f;
  }

  // Metres of floor per pixel.
  double PixelM() const { return 2.0 * half_height_m / height; }

  void AddPolyline(const std::vector<Eigen::Vector2d>& points, double z, const Rgb& color,
                   double width_px) {
    for (std::size_t i = 1; i < points.size(); ++i) {
      AddSegment(points[i - 1], points[i], z, color, width_px);
    }
  }

  // A flat square marker of half size `half_m` (metres on the floor).
  void AddMarker(const Eigen::Vector2d& p, double z, double half_m, const Rgb& color) {
    mjvGeom* g = NewGeom();
    if (g == nullptr) return;
    const float rgba[4] = {color[0], color[1], color[2], 1.0f};
    mjtNum pos[3];
    Lift(p, z, pos);
    const mjtNum size[3] = {half_m, half_m, 0.005};
    mjv_initGeom(g, mjGEOM_BOX, size, pos, nullptr, rgba);
    g->category = mjCAT_DECOR;
    g->emission = 0.0f;
    g->specular = 0.0f;
  }

  // The k-sigma ellipse of a position covariance, as a closed polyline.
  void AddEllipse(const Eigen::Vector2d& center, const Eigen::Matrix2d& P, double k, double z,
                  const Rgb& color) {
    const Eigen::Matrix2d S = 0.5 * (P + P.transpose());
    const double a = S(0, 0), b = S(0, 1), c = S(1, 1);
    if (!(std::isfinite(a) && std::isfinite(b) && std::isfinite(c))) return;
    // Eigen-decomposition of the symmetric 2x2 in closed form.
    const double mean = 0.5 * (a + c);
    const double radius = std::hypot(0.5 * (a - c), b);
    const double l1 = std::max(mean + radius, 0.0);
    const double l2 = std::max(mean - radius, 0.0);
    const double angle = 0.5 * std::atan2(2.0 * b, a - c);
    const Eigen::Vector2d u(std::cos(angle), std::sin(angle));
    const Eigen::Vector2d v(-u.y(), u.x());
    constexpr int kSegments = 32;
    std::vector<Eigen::Vector2d> points;
    for (int i = 0; i <= kSegments; ++i) {
      const double phi = 2.0 * M_PI * i / kSegments;
      points.push_back(center + k * (std::sqrt(l1) * std::cos(phi) * u +
                                     std::sqrt(l2) * std::sin(phi) * v));
    }
    AddPolyline(points, z, color, 2.5);
  }

  // Construction stages.
  void LoadModel(const sim::Scene& scene, const std::vector<double>& rest);
  void UsePlainLook();
  void FrameView(const std::vector<sim::ObstacleFootprint>& obstacles,
                 const Eigen::Vector2d& start);
  void StartOpenGl();

  // Render stages.
  void PlaceRobot(const Pose2& X_WR_true);
  void PointCameraDown();
  void AddLayers(const SceneFrame& frame);
  Image DrawAndRead(const SceneFrame& frame);
  std::vector<LegendEntry> LegendEntries(const SceneFrame& frame) const;
  void DrawLegend(const std::vector<LegendEntry>& entries, double ellipse_scale);
};

SceneRenderer::SceneRenderer(const sim::Scene& scene, const sim::SimParams& sim,
                             const sim::RobotParams& robot, int width, int height)
    : impl_(std::make_unique<Impl>()) {
  MJSLAM_CHECK(width >= 16 && height >= 16);
  Impl& r = *impl_;
  r.width = width;
  r.height = height;
  r.control_point_offset_m = robot.control_point_offset_m;
  r.fontscale = width >= 1280 ? mjFONTSCALE_200 : (width >= 960 ? mjFONTSCALE_150 : mjFONTSCALE_100);
  r.legend_width = width >= kMinWidthForLegend ? kLegendWidth * r.fontscale / 100 : 0;

  // The robot as it rests on the floor at the start: its height and wheel
  // angles after settling are what the renders show, so the physics runs
  // once on the same scene.
  const sim::Simulator settled(scene, sim, robot);
  r.LoadModel(scene, settled.QPos());
  r.UsePlainLook();
  r.FrameView(scene.Obstacles(), settled.X_WR().translation());
  r.StartOpenGl();
}

void SceneRenderer::Impl::LoadModel(const sim::Scene& scene, const std::vector<double>& rest) {
  model = sim::internal::CopyModel(sim::internal::SceneAccess::Model(scene),
                                   "preparing the scene for rendering");
  m = model.get();
  data = sim::internal::MakeData(*m, "preparing the scene for rendering");
  d = data.get();
  rest_qpos = rest;
  MJSLAM_CHECK(static_cast<int>(rest_qpos.size()) == m->nq);
}

void SceneRenderer::Impl::UsePlainLook() {
  // Fast software rendering: no multisampling, few slices; the off-screen
  // buffer is the image.
  m->vis.global.offwidth = width;
  m->vis.global.offheight = height;
  m->vis.quality.offsamples = 0;
  m->vis.quality.numslices = 16;
  m->vis.quality.numstacks = 8;
  m->vis.quality.numquads = 1;
  // Only the headlight, so that a face seen from above shows its own colour
  // (ambient + diffuse = 1): colours in the image are those of colors::.
  for (int i = 0; i < m->nlight; ++i) m->light_active[i] = 0;
  m->vis.headlight.ambient[0] = m->vis.headlight.ambient[1] = m->vis.headlight.ambient[2] = 0.5f;
  m->vis.headlight.diffuse[0] = m->vis.headlight.diffuse[1] = m->vis.headlight.diffuse[2] = 0.5f;
  m->vis.headlight.specular[0] = m->vis.headlight.specular[1] = m->vis.headlight.specular[2] = 0.0f;
  m->vis.headlight.active = 1;

  // Plain colours (textures cost time in software rendering): a light floor,
  // dark grey walls, so that the paths and the map stand out, and a red
  // robot.
  for (int g = 0; g < m->ngeom; ++g) {
    float* rgba = m->geom_rgba + 4 * g;
    if (m->geom_group[g] == sim::internal::kRobotGeomGroup) {
      if (rgba[3] > 0.0f) {
        rgba[0] = colors::kRobot[0];
        rgba[1] = colors::kRobot[1];
        rgba[2] = colors::kRobot[2];
      }
      continue;
    }
    m->geom_matid[g] = -1;
    const float grey = m->geom_type[g] == mjGEOM_PLANE ? kFloorGrey : kWallGrey;
    rgba[0] = rgba[1] = rgba[2] = grey;
    rgba[3] = 1.0f;
  }
}

void SceneRenderer::Impl::FrameView(const std::vector<sim::ObstacleFootprint>& obstacles,
                                    const Eigen::Vector2d& start) {
  // The floor area to show: the obstacles' footprints and the start with a
  // margin, at the aspect of the scene viewport.
  Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
  for (const sim::ObstacleFootprint& o : obstacles) {
    const double c = std::cos(o.X_WO.theta), s = std::sin(o.X_WO.theta);
    Eigen::Vector2d half;
    if (o.shape == sim::ObstacleFootprint::Shape::kRectangle) {
      half = {std::abs(c) * o.half_extents_m.x() + std::abs(s) * o.half_extents_m.y(),
              std::abs(s) * o.half_extents_m.x() + std::abs(c) * o.half_extents_m.y()};
    } else {
      half = {o.radius_m, o.radius_m};
    }
    lo = lo.cwiseMin(o.X_WO.translation() - half);
    hi = hi.cwiseMax(o.X_WO.translation() + half);
  }
  lo = lo.cwiseMin(start - Eigen::Vector2d(1.0, 1.0));
  hi = hi.cwiseMax(start + Eigen::Vector2d(1.0, 1.0));
  const double margin_m = 0.04 * std::max(hi.x() - lo.x(), hi.y() - lo.y());
  view_center = 0.5 * (lo + hi);
  const double aspect = static_cast<double>(width - legend_width) / height;
  half_height_m = std::max(0.5 * (hi.y() - lo.y()), 0.5 * (hi.x() - lo.x()) / aspect) + margin_m;
  half_width_m = half_height_m * aspect;
}

void SceneRenderer::Impl::StartOpenGl() {
  // OSMesa: a software OpenGL context drawing into memory. Mesa would cache
  // its compiled shaders under the home folder (~/.cache/mesa_shader_cache):
  // a render writes only into its run directory (unless the user set these).
  ::setenv("MESA_SHADER_CACHE_DISABLE", "true", 0);
  ::setenv("MESA_GLSL_CACHE_DISABLE", "true", 0);
  const OsMesaApi& osmesa = LoadOsMesa();
  gl = osmesa.create_context_ext(OSMESA_RGBA, 24, 8, 8, nullptr);
  if (gl == nullptr) throw std::runtime_error("OSMesa: cannot create an OpenGL context");
  gl_buffer.resize(static_cast<std::size_t>(width) * height * 4);
  if (!osmesa.make_current(gl, gl_buffer.data(), GL_UNSIGNED_BYTE, width, height)) {
    throw std::runtime_error("OSMesa: cannot make the OpenGL context current");
  }

  // MuJoCo's abstract scene and its OpenGL context, drawing off-screen.
  mjv_defaultCamera(&cam);
  mjv_defaultOption(&opt);
  for (int i = 0; i < mjNGROUP; ++i) {
    opt.geomgroup[i] = 1;  // the robot is group 5
    opt.sitegroup[i] = 0;  // no start, tour or laser sites
  }
  sim::CallMujoco("starting MuJoCo's renderer", [&] {
    mjv_makeScene(m, &scn, m->ngeom + kMaxGeoms);
    scn.flags[mjRND_SHADOW] = 0;
    scn.flags[mjRND_REFLECTION] = 0;
    scn.flags[mjRND_SKYBOX] = 0;
    scn.flags[mjRND_FOG] = 0;
    mjr_makeContext(m, &con, fontscale);
    mjr_setBuffer(mjFB_OFFSCREEN, &con);
  });
  if (con.currentBuffer != mjFB_OFFSCREEN) {
    throw std::runtime_error("MuJoCo: the off-screen buffer is not available");
  }
  readback.resize(static_cast<std::size_t>(width) * height * 3);
}

SceneRenderer::~SceneRenderer() = default;

int SceneRenderer::width() const { return impl_->width; }
int SceneRenderer::height() const { return impl_->height; }

Eigen::Vector2d SceneRenderer::PixelOf(const Eigen::Vector2d& p_W) const {
  const Impl& r = *impl_;
  const int scene_width = r.width - r.legend_width;
  const Eigen::Vector2d d = p_W - r.view_center;
  return {0.5 * scene_width + d.x() / r.half_width_m * 0.5 * scene_width,
          0.5 * r.height - d.y() / r.half_height_m * 0.5 * r.height};
}

Image SceneRenderer::Render(const SceneFrame& frame) {
  Impl& r = *impl_;
  r.PlaceRobot(frame.X_WR_true);
  r.PointCameraDown();
  r.AddLayers(frame);
  return r.DrawAndRead(frame);
}

void SceneRenderer::Impl::PlaceRobot(const Pose2& X_WR_true) {
  // The robot at its true pose (the body origin is the axle centre A), at
  // its rest height and wheel angles; the world's geoms into the scene.
  const Pose2 X_WA = X_WR_true * Pose2(-control_point_offset_m, 0.0, 0.0);
  std::copy(rest_qpos.begin(), rest_qpos.end(), d->qpos);
  d->qpos[0] = X_WA.x;
  d->qpos[1] = X_WA.y;
  d->qpos[3] = std::cos(0.5 * X_WA.theta);
  d->qpos[4] = 0.0;
  d->qpos[5] = 0.0;
  d->qpos[6] = std::sin(0.5 * X_WA.theta);
  sim::CallMujoco("updating the rendered scene", [&] {
    mj_kinematics(m, d);
    mj_camlight(m, d);
    mjv_updateScene(m, d, &opt, nullptr, &cam, mjCAT_ALL, &scn);
  });
}

void SceneRenderer::Impl::PointCameraDown() {
  // The camera straight above the view centre, north up.
  const double near_m = kCameraHeightM - 5.0;
  for (mjvGLCamera& c : scn.camera) {
    c.pos[0] = static_cast<float>(view_center.x());
    c.pos[1] = static_cast<float>(view_center.y());
    c.pos[2] = static_cast<float>(kCameraHeightM);
    c.forward[0] = 0.0f;
    c.forward[1] = 0.0f;
    c.forward[2] = -1.0f;
    c.up[0] = 0.0f;
    c.up[1] = 1.0f;
    c.up[2] = 0.0f;
    c.frustum_center = 0.0f;
    c.frustum_top = static_cast<float>(half_height_m * near_m / kCameraHeightM);
    c.frustum_bottom = -c.frustum_top;
    c.frustum_near = static_cast<float>(near_m);
    c.frustum_far = static_cast<float>(kCameraHeightM + 1.0);
  }
  scn.enabletransform = 0;
  // Matte surfaces: a specular highlight would wash out the top faces.
  for (int i = 0; i < scn.ngeom; ++i) scn.geoms[i].specular = 0.0f;
  // Beyond the floor plane: a floor-coloured slab under the whole view.
  mjvGeom* g = NewGeom();
  const float rgba[4] = {kFloorGrey, kFloorGrey, kFloorGrey, 1.0f};
  const mjtNum size[3] = {2.0 * half_width_m, 2.0 * half_height_m, 0.01};
  const mjtNum pos[3] = {view_center.x(), view_center.y(), -0.05};
  mjv_initGeom(g, mjGEOM_BOX, size, pos, nullptr, rgba);
  g->category = mjCAT_DECOR;
  g->specular = 0.0f;
}

void SceneRenderer::Impl::AddLayers(const SceneFrame& frame) {
  // Layers, bottom to top: planned path and frontier, true path, estimated
  // paths; then the maps, the laser hits and the ellipses above the walls.
  const double pixel_m = 2.0 * half_height_m / height;
  if (frame.explorer) {
    AddPolyline(frame.explorer->path, kFloorLayerZ, colors::kPlannedPath, 2.0);
    for (const Eigen::Vector2d& p : frame.explorer->frontier) {
      AddMarker(p, kFloorLayerZ, 1.5 * pixel_m, colors::kFrontier);
    }
    if (frame.explorer->goal) AddMarker(*frame.explorer->goal, kFloorLayerZ + 0.01, 4.0 * pixel_m, colors::kGoal);
  }
  // The estimates and the truth often overlap: the first filter is drawn
  // widest, the next narrower on top, the truth thinnest on top of all, so
  // each stays visible as a stripe of its own.
  const std::size_t n = frame.filters.size();
  auto width_of = [n](std::size_t i) { return 2.0 + 2.0 * static_cast<double>(n - i); };
  for (std::size_t i = 0; i < n; ++i) {
    AddPolyline(frame.filters[i].path, kFloorLayerZ + 0.01 * (i + 1), frame.filters[i].color, width_of(i));
  }
  AddPolyline(frame.true_path, kFloorLayerZ + 0.01 * (n + 1), colors::kTruth, 1.5);
  for (std::size_t i = 0; i < n; ++i) {
    const FilterLayer& f = frame.filters[i];
    for (const Segment2& s : f.lines) AddSegment(s.a, s.b, kMapLayerZ + 0.005 * i, f.color, width_of(i));
    const double half_m = (1.5 + 1.5 * static_cast<double>(n - i)) * pixel_m;
    for (const Eigen::Vector2d& p : f.corners) AddMarker(p, kMapLayerZ + 0.005 * i, half_m, f.color);
  }
  for (std::size_t i = 0; i < n; ++i) {
    // Submap starts: a bar across the path, 16 pixels long.
    const FilterLayer& f = frame.filters[i];
    for (const Pose2& X_WR : f.submap_starts) {
      const Eigen::Vector2d across =
          8.0 * pixel_m * Eigen::Vector2d(-std::sin(X_WR.theta), std::cos(X_WR.theta));
      AddSegment(X_WR.translation() - across, X_WR.translation() + across, kEllipseLayerZ, f.color,
                 3.0);
    }
  }
  for (const Eigen::Vector2d& p : frame.laser_hits) AddMarker(p, kHitLayerZ, 1.0 * pixel_m, colors::kLaserHits);
  for (std::size_t i = 0; i < frame.filters.size(); ++i) {
    const FilterLayer& f = frame.filters[i];
    if (f.X_WR) {
      AddEllipse(f.X_WR->translation(), f.P_xy, 2.0 * frame.ellipse_scale, kEllipseLayerZ + 0.01 * i, f.color);
    }
  }
}

Image SceneRenderer::Impl::DrawAndRead(const SceneFrame& frame) {
  // The legend's lines and the time are prepared first: the trapped MuJoCo
  // calls below may only touch plain data.
  const std::vector<LegendEntry> legend =
      legend_width > 0 ? LegendEntries(frame) : std::vector<LegendEntry>();
  char time_text[64];
  std::snprintf(time_text, sizeof(time_text), "t = %.1f s", frame.t_s);

  // Render, then the 2D overlays, then read back.
  const mjrRect full = {0, 0, width, height};
  sim::CallMujoco("drawing a frame", [&] {
    mjr_rectangle(full, 1.0f, 1.0f, 1.0f, 1.0f);
    mjr_render(SceneViewport(), &scn, &con);
    mjr_overlay(mjFONT_NORMAL, mjGRID_TOPLEFT, SceneViewport(), time_text, nullptr, &con);
    if (legend_width > 0) DrawLegend(legend, frame.ellipse_scale);
    mjr_readPixels(readback.data(), nullptr, full, &con);
  });

  // OpenGL rows are bottom-up.
  Image image;
  image.width = width;
  image.height = height;
  image.rgb.resize(readback.size());
  const std::size_t row_bytes = static_cast<std::size_t>(width) * 3;
  for (int y = 0; y < height; ++y) {
    std::memcpy(image.rgb.data() + y * row_bytes,
                readback.data() + (height - 1 - y) * row_bytes, row_bytes);
  }
  return image;
}

std::vector<LegendEntry> SceneRenderer::Impl::LegendEntries(const SceneFrame& frame) const {
  std::vector<LegendEntry> entries = {{"true path", colors::kTruth}};
  for (const FilterLayer& f : frame.filters) {
    entries.push_back({f.name, f.color});
    if (!f.submap_starts.empty()) entries.push_back({"  | new submap", f.color});
  }
  entries.push_back({"laser hits", colors::kLaserHits});
  entries.push_back({"robot (true pose)", colors::kRobot});
  if (frame.explorer) {
    entries.push_back({"frontier, goal", colors::kFrontier});
    entries.push_back({"planned path", colors::kPlannedPath});
  }
  return entries;
}

// Runs inside a trapped MuJoCo call: plain data only (no object with a
// destructor is created here).
void SceneRenderer::Impl::DrawLegend(const std::vector<LegendEntry>& entries,
                                     double ellipse_scale) {
  const mjrRect panel = {width - legend_width, 0, legend_width, height};
  mjr_rectangle(panel, 1.0f, 1.0f, 1.0f, 1.0f);
  const int line_height = con.charHeight + 6 * fontscale / 100;
  const int swatch = con.charHeight - 2;
  const int x0 = panel.left + 8 * fontscale / 100;
  int y = height - 10 * fontscale / 100 - line_height;
  // Each entry: a swatch and its name, left-aligned by padding the label
  // (mjr_label centres its text).
  const int label_left = x0 + swatch + 6 * fontscale / 100;
  const int label_width = panel.left + panel.width - label_left - 4;
  auto label_at = [&](const char* text, int left, int bottom, int label_w) {
    mjr_label({left, bottom, label_w, line_height}, mjFONT_NORMAL, text, 1.0f, 1.0f, 1.0f, 1.0f,
              0.0f, 0.0f, 0.0f, &con);
  };
  for (const LegendEntry& e : entries) {
    mjr_rectangle({x0, y + (line_height - swatch) / 2, swatch, swatch}, e.color[0], e.color[1],
                  e.color[2], 1.0f);
    label_at(e.text.c_str(), label_left, y, label_width);
    y -= line_height;
  }
  char scale_text[64];
  std::snprintf(scale_text, sizeof(scale_text), "ellipses 2sd x%g", ellipse_scale);
  label_at(scale_text, x0, y, panel.left + panel.width - x0 - 4);
  y -= line_height;

  // A scale bar: the largest whole number of metres (1, 2 or 5 times a
  // power of ten) that fits in the swatch column plus half the panel.
  const double pixels_per_m = 1.0 / PixelM();
  const double fit_m = (0.5 * legend_width) / pixels_per_m;
  double bar_m = std::pow(10.0, std::floor(std::log10(fit_m)));
  if (5.0 * bar_m <= fit_m) {
    bar_m *= 5.0;
  } else if (2.0 * bar_m <= fit_m) {
    bar_m *= 2.0;
  }
  const int bar_px = static_cast<int>(std::lround(bar_m * pixels_per_m));
  y -= line_height / 2;
  mjr_rectangle({x0, y + line_height / 2 - 2, bar_px, 4}, 0.0f, 0.0f, 0.0f, 1.0f);
  char bar_text[32];
  std::snprintf(bar_text, sizeof(bar_text), "%g m", bar_m);
  label_at(bar_text, x0 + bar_px + 4, y, panel.left + panel.width - (x0 + bar_px + 4) - 4);
}

}  // namespace mjslam::renders
