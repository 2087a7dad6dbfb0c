// Exports a scene as our renderer sees it, for bench/vs_mitsuba.py: the geometry after our loader
// (world-space triangles, split by material, as binary PLY; spheres as spheres), the materials,
// the lights and the comparison framing's camera, as one JSON file the script turns into a Mitsuba 3
// scene dictionary. The camera is the course's framing at the size: its crop of the 800x600 view,
// as `pathtracer -r W H` renders (or with --whole-view the whole view scaled, as --keep-fov), with
// a thin lens of --aperture (radius) and --focal-distance. Kinds Mitsuba's comparison does not need
// (point, spot, directional, ambient lights) are refused with a message, never skipped.
//
//   ./build/bench_export_mitsuba scene.dae OUT_DIR [--width 480 --height 360] [--whole-view]
//                                [--aperture R --focal-distance D]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "args.h"
#include "camera.h"
#include "scene_file.h"

namespace {

using nlohmann::json;
using pt::Vec3;

json vec(Vec3 v) { return json::array({v.x, v.y, v.z}); }

// A binary PLY of the triangles `indices` over `positions`, with the file's shading normals where
// it has them: Mitsuba would otherwise make its own from the faces, and the renderers would shade
// curved meshes differently.
void write_ply(const std::string& path, const std::vector<Vec3>& positions, const std::vector<Vec3>& normals,
               const std::vector<uint32_t>& indices) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw std::runtime_error(path + ": cannot write");
  const bool with_normals = normals.size() == positions.size();
  out << "ply\nformat binary_little_endian 1.0\nelement vertex " << positions.size()
      << "\nproperty float x\nproperty float y\nproperty float z\n"
      << (with_normals ? "property float nx\nproperty float ny\nproperty float nz\n" : "") << "element face "
      << indices.size() / 3 << "\nproperty list uchar int vertex_indices\nend_header\n";
  if (with_normals) {
    for (size_t i = 0; i < positions.size(); ++i) {
      const Vec3 pair[2] = {positions[i], normals[i]};
      out.write(reinterpret_cast<const char*>(pair), sizeof pair);
    }
  } else {
    out.write(reinterpret_cast<const char*>(positions.data()), std::streamsize(positions.size() * sizeof(Vec3)));
  }
  for (size_t t = 0; t < indices.size(); t += 3) {
    unsigned char three = 3;
    int32_t idx[3] = {int32_t(indices[t]), int32_t(indices[t + 1]), int32_t(indices[t + 2])};
    out.write(reinterpret_cast<const char*>(&three), 1);
    out.write(reinterpret_cast<const char*>(idx), sizeof idx);
  }
  if (!out) throw std::runtime_error(path + ": write failed");
}

json material_json(const pt::Material& m) {
  json j = {{"name", m.name}, {"type", pt::material_type_name(m.type)}, {"albedo", vec(m.albedo)},
            {"transmittance", vec(m.transmittance)}, {"ior", m.ior}, {"alpha", m.alpha}, {"eta", vec(m.eta)},
            {"k", vec(m.k)}, {"radiance", vec(m.radiance)}};
  return j;
}

}  // namespace

int main(int argc, char** argv) {
  bench::Args args(argc, argv, "bench_export_mitsuba scene.dae OUT_DIR [--width W=480 --height H=360] [--whole-view] "
                               "[--aperture R=0 --focal-distance D=4.7]");
  const int width = args.integer("--width", 480, 1, 16384), height = args.integer("--height", 360, 1, 16384);
  const bool whole_view = args.flag("--whole-view");
  auto real = [&](const char* name, double def) {
    const std::string v = args.value(name, "");
    if (v.empty()) return def;
    char* end = nullptr;
    const double x = std::strtod(v.c_str(), &end);
    if (*end || !std::isfinite(x) || x < 0) args.fail(std::string(name) + " must be a number of at least 0");
    return x;
  };
  const double aperture = real("--aperture", 0), focal_distance = real("--focal-distance", pt::kCourseFocalDistance);
  const std::vector<std::string> files = args.positional();
  args.finish();
  if (files.size() != 2) args.fail("needs a scene file and an output folder");
  try {
    const std::string& scene_path = files[0];
    const std::string& out_dir = files[1];
    pt::SceneDesc desc = pt::load_scene(scene_path);

    json scene;
    pt::CameraParams cp;
    cp.width = width;
    cp.height = height;
    cp.keep_fov = whole_view;
    pt::Camera cam = pt::make_camera(desc, cp);
    scene["camera"] = {{"origin", vec(cam.position)}, {"target", vec(cam.position - cam.back)}, {"up", vec(cam.up)},
                       {"fov_x_deg", 2 * std::atan(cam.tan_half_w) * 180 / M_PI},
                       {"fov_y_deg", 2 * std::atan(cam.tan_half_h) * 180 / M_PI},
                       {"width", width}, {"height", height},
                       {"lens_radius", aperture}, {"focal_distance", focal_distance}};
    scene["materials"] = json::array();
    for (const pt::Material& m : desc.materials) scene["materials"].push_back(material_json(m));

    // Triangles per (mesh, material), so that each Mitsuba shape has one BSDF.
    scene["meshes"] = json::array();
    for (size_t mi = 0; mi < desc.meshes.size(); ++mi) {
      const pt::MeshDesc& mesh = desc.meshes[mi];
      std::map<int, std::vector<uint32_t>> by_material;
      for (size_t t = 0; t < mesh.indices.size() / 3; ++t)
        for (int c = 0; c < 3; ++c) by_material[mesh.tri_material[t]].push_back(mesh.indices[3 * t + c]);
      for (auto& [material, indices] : by_material) {
        std::string file = "mesh" + std::to_string(mi) + "_m" + std::to_string(material) + ".ply";
        write_ply(out_dir + "/" + file, mesh.positions, mesh.normals, indices);
        scene["meshes"].push_back({{"file", file}, {"material", material}, {"smooth", !mesh.normals.empty()}});
      }
    }
    scene["spheres"] = json::array();
    for (const pt::SphereDesc& s : desc.spheres)
      scene["spheres"].push_back({{"center", vec(s.center)}, {"radius", s.radius}, {"material", s.material}});
    scene["area_lights"] = json::array();
    for (const pt::LightDesc& l : desc.lights) {
      if (l.type != pt::LightType::area)
        throw std::runtime_error(scene_path + ": light '" + l.name + "' is a " + pt::light_type_name(l.type) +
                                 " light; the Mitsuba export handles area lights only");
      // Mitsuba's rectangle emits along +z of its frame: order the edges so x cross y faces the
      // light's direction.
      Vec3 x = l.dim_x * 0.5f, y = l.dim_y * 0.5f, n = pt::normalize(l.direction);
      if (pt::dot(pt::cross(x, y), n) < 0) std::swap(x, y);
      scene["area_lights"].push_back({{"center", vec(l.position)}, {"half_x", vec(x)}, {"half_y", vec(y)},
                                      {"normal", vec(n)}, {"radiance", vec(l.color)}});
    }
    std::ofstream out(out_dir + "/scene.json");
    out << scene.dump(1) << "\n";
    if (!out) throw std::runtime_error(out_dir + "/scene.json: write failed");
    std::printf("%s: %zu mesh parts, %zu spheres, %zu area lights -> %s/scene.json\n", scene_path.c_str(),
                scene["meshes"].size(), desc.spheres.size(), desc.lights.size(), out_dir.c_str());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_export_mitsuba: %s\n", e.what());
    return 1;
  }
}
