#include "renders/scene_renderer.h"

#include <GL/osmesa.h>
#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include "common/check.h"
#include "sim/obstacles.h"
#include "sim/simulator.h"

namespace mjslam::renders {

namespace {

namespace fs = std::filesystem;

// The wrapper MJCF in MuJoCo's virtual file system (see sim/README.md).
constexpr char kSceneFileName[] = "mjslam_render_scene.xml";
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

struct VfsDeleter {
  void operator()(mjVFS* vfs) const {
    mj_deleteVFS(vfs);
    delete vfs;
  }
};

}  // namespace

struct SceneRenderer::Impl {
  int width = 0;
  int height = 0;
  int fontscale = mjFONTSCALE_100;
  int legend_width = 0;
  double control_point_offset_m = 0.0;
  std::vector<double> rest_qpos;

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

  ~Impl() {
    mjr_freeContext(&con);
    mjv_freeScene(&scn);
    if (d != nullptr) mj_deleteData(d);
    if (m != nullptr) mj_deleteModel(m);
    if (gl != nullptr) OSMesaDestroyContext(gl);
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

  void DrawLegend(const SceneFrame& frame);
};

SceneRenderer::SceneRenderer(const std::string& world_path, const std::string& robot_model_path,
                             const sim::SimParams& sim, const sim::RobotParams& robot, int width,
                             int height)
    : impl_(std::make_unique<Impl>()) {
  MJSLAM_CHECK(width >= 16 && height >= 16);
  Impl& r = *impl_;
  r.width = width;
  r.height = height;
  r.control_point_offset_m = robot.control_point_offset_m;
  r.fontscale = width >= 1280 ? mjFONTSCALE_200 : (width >= 960 ? mjFONTSCALE_150 : mjFONTSCALE_100);
  r.legend_width = width >= kMinWidthForLegend ? kLegendWidth * r.fontscale / 100 : 0;

  // The simulator composes and checks the files, and settles the robot: its
  // rest height and wheel angles are what the renders show.
  const sim::Simulator simulator(world_path, robot_model_path, sim, robot);
  r.rest_qpos = simulator.QPos();

  // The same composed scene, loaded here for drawing.
  const fs::path world_dir = fs::path(simulator.world_path()).parent_path();
  const std::string& scene_xml = simulator.SceneXml();
  std::unique_ptr<mjVFS, VfsDeleter> vfs(new mjVFS);
  mj_defaultVFS(vfs.get());
  MJSLAM_CHECK(mj_makeEmptyFileVFS(vfs.get(), kSceneFileName, static_cast<int>(scene_xml.size())) == 0);
  const int file = mj_findFileVFS(vfs.get(), kSceneFileName);
  MJSLAM_CHECK(file >= 0);
  std::memcpy(vfs->filedata[file], scene_xml.data(), scene_xml.size());
  char error[1024] = "";
  r.m = mj_loadXML((world_dir / kSceneFileName).string().c_str(), vfs.get(), error, sizeof(error));
  if (r.m == nullptr) {
    throw std::runtime_error("cannot load the scene of '" + world_path + "' for rendering: " + error);
  }
  r.d = mj_makeData(r.m);
  MJSLAM_CHECK(r.d != nullptr);
  MJSLAM_CHECK(static_cast<int>(r.rest_qpos.size()) == r.m->nq);

  // Fast software rendering: no multisampling, few slices; the off-screen
  // buffer is the image.
  r.m->vis.global.offwidth = width;
  r.m->vis.global.offheight = height;
  r.m->vis.quality.offsamples = 0;
  r.m->vis.quality.numslices = 16;
  r.m->vis.quality.numstacks = 8;
  r.m->vis.quality.numquads = 1;
  // Only the headlight, so that a face seen from above shows its own colour
  // (ambient + diffuse = 1): colours in the image are those of colors::.
  for (int i = 0; i < r.m->nlight; ++i) r.m->light_active[i] = 0;
  r.m->vis.headlight.ambient[0] = r.m->vis.headlight.ambient[1] = r.m->vis.headlight.ambient[2] = 0.5f;
  r.m->vis.headlight.diffuse[0] = r.m->vis.headlight.diffuse[1] = r.m->vis.headlight.diffuse[2] = 0.5f;
  r.m->vis.headlight.specular[0] = r.m->vis.headlight.specular[1] = r.m->vis.headlight.specular[2] = 0.0f;
  r.m->vis.headlight.active = 1;

  // Plain colours (textures cost time in software rendering): a light floor,
  // dark grey walls, so that the paths and the map stand out, and a red
  // robot.
  for (int g = 0; g < r.m->ngeom; ++g) {
    float* rgba = r.m->geom_rgba + 4 * g;
    if (r.m->geom_group[g] == 5) {
      if (rgba[3] > 0.0f) {
        rgba[0] = colors::kRobot[0];
        rgba[1] = colors::kRobot[1];
        rgba[2] = colors::kRobot[2];
      }
      continue;
    }
    r.m->geom_matid[g] = -1;
    const float grey = r.m->geom_type[g] == mjGEOM_PLANE ? kFloorGrey : kWallGrey;
    rgba[0] = rgba[1] = rgba[2] = grey;
    rgba[3] = 1.0f;
  }

  // The floor area to show: the obstacles' footprints with a margin, at the
  // aspect of the scene viewport.
  Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
  for (const sim::ObstacleFootprint& o : simulator.Obstacles()) {
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
  const Eigen::Vector2d start = simulator.X_WR().translation();
  lo = lo.cwiseMin(start - Eigen::Vector2d(1.0, 1.0));
  hi = hi.cwiseMax(start + Eigen::Vector2d(1.0, 1.0));
  const double margin_m = 0.04 * std::max(hi.x() - lo.x(), hi.y() - lo.y());
  r.view_center = 0.5 * (lo + hi);
  const double aspect = static_cast<double>(width - r.legend_width) / height;
  r.half_height_m = std::max(0.5 * (hi.y() - lo.y()), 0.5 * (hi.x() - lo.x()) / aspect) + margin_m;
  r.half_width_m = r.half_height_m * aspect;

  // OSMesa: a software OpenGL context drawing into memory.
  r.gl = OSMesaCreateContextExt(OSMESA_RGBA, 24, 8, 8, nullptr);
  if (r.gl == nullptr) throw std::runtime_error("OSMesa: cannot create an OpenGL context");
  r.gl_buffer.resize(static_cast<std::size_t>(width) * height * 4);
  if (!OSMesaMakeCurrent(r.gl, r.gl_buffer.data(), GL_UNSIGNED_BYTE, width, height)) {
    throw std::runtime_error("OSMesa: cannot make the OpenGL context current");
  }

  mjv_defaultCamera(&r.cam);
  mjv_defaultOption(&r.opt);
  for (int i = 0; i < mjNGROUP; ++i) {
    r.opt.geomgroup[i] = 1;  // the robot is group 5
    r.opt.sitegroup[i] = 0;  // no start, tour or laser sites
  }
  mjv_defaultScene(&r.scn);
  mjv_makeScene(r.m, &r.scn, r.m->ngeom + kMaxGeoms);
  r.scn.flags[mjRND_SHADOW] = 0;
  r.scn.flags[mjRND_REFLECTION] = 0;
  r.scn.flags[mjRND_SKYBOX] = 0;
  r.scn.flags[mjRND_FOG] = 0;
  mjr_defaultContext(&r.con);
  mjr_makeContext(r.m, &r.con, r.fontscale);
  mjr_setBuffer(mjFB_OFFSCREEN, &r.con);
  if (r.con.currentBuffer != mjFB_OFFSCREEN) {
    throw std::runtime_error("MuJoCo: the off-screen buffer is not available");
  }
  r.readback.resize(static_cast<std::size_t>(width) * height * 3);
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

  // The robot at its true pose: the body origin is the axle centre A.
  const Pose2 X_WA = frame.X_WR_true * Pose2(-r.control_point_offset_m, 0.0, 0.0);
  std::copy(r.rest_qpos.begin(), r.rest_qpos.end(), r.d->qpos);
  r.d->qpos[0] = X_WA.x;
  r.d->qpos[1] = X_WA.y;
  r.d->qpos[3] = std::cos(0.5 * X_WA.theta);
  r.d->qpos[4] = 0.0;
  r.d->qpos[5] = 0.0;
  r.d->qpos[6] = std::sin(0.5 * X_WA.theta);
  mj_kinematics(r.m, r.d);
  mj_camlight(r.m, r.d);
  mjv_updateScene(r.m, r.d, &r.opt, nullptr, &r.cam, mjCAT_ALL, &r.scn);

  // The camera straight above the view centre, north up.
  const double near_m = kCameraHeightM - 5.0;
  for (mjvGLCamera& c : r.scn.camera) {
    c.pos[0] = static_cast<float>(r.view_center.x());
    c.pos[1] = static_cast<float>(r.view_center.y());
    c.pos[2] = static_cast<float>(kCameraHeightM);
    c.forward[0] = 0.0f;
    c.forward[1] = 0.0f;
    c.forward[2] = -1.0f;
    c.up[0] = 0.0f;
    c.up[1] = 1.0f;
    c.up[2] = 0.0f;
    c.frustum_center = 0.0f;
    c.frustum_top = static_cast<float>(r.half_height_m * near_m / kCameraHeightM);
    c.frustum_bottom = -c.frustum_top;
    c.frustum_near = static_cast<float>(near_m);
    c.frustum_far = static_cast<float>(kCameraHeightM + 1.0);
  }
  r.scn.enabletransform = 0;
  // Matte surfaces: a specular highlight would wash out the top faces.
  for (int i = 0; i < r.scn.ngeom; ++i) r.scn.geoms[i].specular = 0.0f;
  // Beyond the floor plane: a floor-coloured slab under the whole view.
  {
    mjvGeom* g = r.NewGeom();
    const float rgba[4] = {kFloorGrey, kFloorGrey, kFloorGrey, 1.0f};
    const mjtNum size[3] = {2.0 * r.half_width_m, 2.0 * r.half_height_m, 0.01};
    const mjtNum pos[3] = {r.view_center.x(), r.view_center.y(), -0.05};
    mjv_initGeom(g, mjGEOM_BOX, size, pos, nullptr, rgba);
    g->category = mjCAT_DECOR;
    g->specular = 0.0f;
  }

  // Layers, bottom to top: planned path and frontier, true path, estimated
  // paths; then the maps, the laser hits and the ellipses above the walls.
  const double pixel_m = 2.0 * r.half_height_m / r.height;
  if (frame.explorer) {
    r.AddPolyline(frame.explorer->path, kFloorLayerZ, colors::kPlannedPath, 2.0);
    for (const Eigen::Vector2d& p : frame.explorer->frontier) {
      r.AddMarker(p, kFloorLayerZ, 1.5 * pixel_m, colors::kFrontier);
    }
    if (frame.explorer->goal) r.AddMarker(*frame.explorer->goal, kFloorLayerZ + 0.01, 4.0 * pixel_m, colors::kGoal);
  }
  // The estimates and the truth often overlap: the first filter is drawn
  // widest, the next narrower on top, the truth thinnest on top of all, so
  // each stays visible as a stripe of its own.
  const std::size_t n = frame.filters.size();
  auto width_of = [n](std::size_t i) { return 2.0 + 2.0 * static_cast<double>(n - i); };
  for (std::size_t i = 0; i < n; ++i) {
    r.AddPolyline(frame.filters[i].path, kFloorLayerZ + 0.01 * (i + 1), frame.filters[i].color, width_of(i));
  }
  r.AddPolyline(frame.true_path, kFloorLayerZ + 0.01 * (n + 1), colors::kTruth, 1.5);
  for (std::size_t i = 0; i < n; ++i) {
    const FilterLayer& f = frame.filters[i];
    for (const Segment2& s : f.lines) r.AddSegment(s.a, s.b, kMapLayerZ + 0.005 * i, f.color, width_of(i));
    const double half_m = (1.5 + 1.5 * static_cast<double>(n - i)) * pixel_m;
    for (const Eigen::Vector2d& p : f.corners) r.AddMarker(p, kMapLayerZ + 0.005 * i, half_m, f.color);
  }
  for (const Eigen::Vector2d& p : frame.laser_hits) r.AddMarker(p, kHitLayerZ, 1.0 * pixel_m, colors::kLaserHits);
  for (std::size_t i = 0; i < frame.filters.size(); ++i) {
    const FilterLayer& f = frame.filters[i];
    if (f.X_WR) {
      r.AddEllipse(f.X_WR->translation(), f.P_xy, 2.0 * frame.ellipse_scale, kEllipseLayerZ + 0.01 * i, f.color);
    }
  }

  // Render, then the 2D overlays.
  const mjrRect full = {0, 0, r.width, r.height};
  mjr_rectangle(full, 1.0f, 1.0f, 1.0f, 1.0f);
  mjr_render(r.SceneViewport(), &r.scn, &r.con);
  char time_text[64];
  std::snprintf(time_text, sizeof(time_text), "t = %.1f s", frame.t_s);
  mjr_overlay(mjFONT_NORMAL, mjGRID_TOPLEFT, r.SceneViewport(), time_text, nullptr, &r.con);
  if (r.legend_width > 0) r.DrawLegend(frame);

  // Read back (OpenGL rows are bottom-up).
  mjr_readPixels(r.readback.data(), nullptr, full, &r.con);
  Image image;
  image.width = r.width;
  image.height = r.height;
  image.rgb.resize(r.readback.size());
  const std::size_t row_bytes = static_cast<std::size_t>(r.width) * 3;
  for (int y = 0; y < r.height; ++y) {
    std::memcpy(image.rgb.data() + y * row_bytes,
                r.readback.data() + (r.height - 1 - y) * row_bytes, row_bytes);
  }
  return image;
}

void SceneRenderer::Impl::DrawLegend(const SceneFrame& frame) {
  const mjrRect panel = {width - legend_width, 0, legend_width, height};
  mjr_rectangle(panel, 1.0f, 1.0f, 1.0f, 1.0f);
  struct Entry {
    std::string text;
    Rgb color;
  };
  std::vector<Entry> entries = {{"true path", colors::kTruth}};
  for (const FilterLayer& f : frame.filters) entries.push_back({f.name, f.color});
  entries.push_back({"laser hits", colors::kLaserHits});
  entries.push_back({"robot (true pose)", colors::kRobot});
  if (frame.explorer) {
    entries.push_back({"frontier, goal", colors::kFrontier});
    entries.push_back({"planned path", colors::kPlannedPath});
  }
  const int line_height = con.charHeight + 6 * fontscale / 100;
  const int swatch = con.charHeight - 2;
  const int x0 = panel.left + 8 * fontscale / 100;
  int y = height - 10 * fontscale / 100 - line_height;
  // Each entry: a swatch and its name, left-aligned by padding the label
  // (mjr_label centres its text).
  const int label_left = x0 + swatch + 6 * fontscale / 100;
  const int label_width = panel.left + panel.width - label_left - 4;
  auto label_at = [&](const std::string& text, int left, int bottom, int label_w) {
    mjr_label({left, bottom, label_w, line_height}, mjFONT_NORMAL, text.c_str(), 1.0f, 1.0f, 1.0f, 1.0f,
              0.0f, 0.0f, 0.0f, &con);
  };
  for (const Entry& e : entries) {
    mjr_rectangle({x0, y + (line_height - swatch) / 2, swatch, swatch}, e.color[0], e.color[1],
                  e.color[2], 1.0f);
    label_at(e.text, label_left, y, label_width);
    y -= line_height;
  }
  char scale_text[64];
  std::snprintf(scale_text, sizeof(scale_text), "ellipses 2sd x%g", frame.ellipse_scale);
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
