// Small COLLADA documents for the loader's tests (test_collada*.cpp): builders for each element
// of the CS184 dialect, a probe that recovers a node's world transform, and checks for located
// SceneErrors.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "collada.h"

namespace pt {
namespace collada_docs {

// ---- small documents ----

// A whole COLLADA document. `libs` are library sections, `nodes` the visual scene's children.
// `up` is the <up_axis> text; "" writes an <asset> without <up_axis>, "-" writes no <asset>.
inline std::string dae(const std::string& nodes, const std::string& libs, const std::string& up = "Y_UP") {
  std::string s =
      "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n"
      "<COLLADA xmlns=\"http://www.collada.org/2005/11/COLLADASchema\" version=\"1.4.1\">\n";
  if (up != "-") {
    s += "<asset>\n";
    if (!up.empty()) s += "<up_axis>" + up + "</up_axis>\n";
    s += "</asset>\n";
  }
  s += libs;
  s += "<library_visual_scenes>\n<visual_scene id=\"Scene\">\n" + nodes + "</visual_scene>\n</library_visual_scenes>\n";
  s += "<scene>\n<instance_visual_scene url=\"#Scene\"/>\n</scene>\n</COLLADA>\n";
  return s;
}

inline size_t count_tokens(const std::string& s) {
  std::istringstream in(s);
  std::string t;
  size_t n = 0;
  while (in >> t) ++n;
  return n;
}

// A <geometry id=id> mesh over `positions` (x y z ...); in `prims` "#V" names the mesh's <vertices>.
inline std::string mesh_geometry(const std::string& id, const std::string& positions, std::string prims) {
  for (size_t at; (at = prims.find("\"#V\"")) != std::string::npos;) prims.replace(at, 4, "\"#" + id + "-v\"");
  return "<geometry id=\"" + id + "\">\n<mesh>\n<source id=\"" + id + "-pos\">\n<float_array id=\"" + id +
         "-arr\" count=\"" + std::to_string(count_tokens(positions)) + "\">" + positions + "</float_array>\n" +
         "<technique_common>\n<accessor source=\"#" + id + "-arr\" count=\"" +
         std::to_string(count_tokens(positions) / 3) + "\" stride=\"3\"/>\n</technique_common>\n</source>\n" +
         "<vertices id=\"" + id + "-v\">\n<input semantic=\"POSITION\" source=\"#" + id + "-pos\"/>\n</vertices>\n" +
         prims + "</mesh>\n</geometry>\n";
}

inline std::string polylist(const std::string& vcount, const std::string& p, const std::string& material = "") {
  std::string m = material.empty() ? "" : " material=\"" + material + "\"";
  return "<polylist" + m + " count=\"" + std::to_string(count_tokens(vcount)) +
         "\">\n<input semantic=\"VERTEX\" source=\"#V\" offset=\"0\"/>\n<vcount>" + vcount + "</vcount>\n<p>" + p +
         "</p>\n</polylist>\n";
}

inline std::string triangles(const std::string& p, const std::string& material = "") {
  std::string m = material.empty() ? "" : " material=\"" + material + "\"";
  return "<triangles" + m + " count=\"" + std::to_string(count_tokens(p) / 3) +
         "\">\n<input semantic=\"VERTEX\" source=\"#V\" offset=\"0\"/>\n<p>" + p + "</p>\n</triangles>\n";
}

inline std::string sphere_geometry(const std::string& id, const std::string& radius) {
  return "<geometry id=\"" + id + "\">\n<extra>\n<technique profile=\"CGL\">\n<sphere>\n<radius>" + radius +
         "</radius>\n</sphere>\n</technique>\n</extra>\n</geometry>\n";
}

// A material `id` whose effect holds `effect_body`.
inline std::string material(const std::string& id, const std::string& effect_body) {
  return "<library_effects>\n<effect id=\"" + id + "-fx\">\n" + effect_body +
         "</effect>\n</library_effects>\n<library_materials>\n<material id=\"" + id + "\">\n<instance_effect url=\"#" +
         id + "-fx\"/>\n</material>\n</library_materials>\n";
}
inline std::string phong(const std::string& shader, const std::string& diffuse) {
  return "<profile_COMMON>\n<technique sid=\"common\">\n<" + shader + ">\n<diffuse>\n<color sid=\"diffuse\">" + diffuse +
         "</color>\n</diffuse>\n</" + shader + ">\n</technique>\n</profile_COMMON>\n";
}
inline std::string cgl(const std::string& body) { return "<extra>\n<technique profile=\"CGL\">\n" + body + "</technique>\n</extra>\n"; }

// A node instancing geometry `url`, with `transforms` and {symbol, target} material bindings.
inline std::string geom_node(const std::string& url, const std::string& transforms = "",
                      const std::vector<std::pair<std::string, std::string>>& binds = {}) {
  std::string s = "<node>\n" + transforms + "<instance_geometry url=\"" + url + "\">\n";
  if (!binds.empty()) {
    s += "<bind_material>\n<technique_common>\n";
    for (auto& [sym, target] : binds)
      s += "<instance_material symbol=\"" + sym + "\" target=\"" + target + "\"/>\n";
    s += "</technique_common>\n</bind_material>\n";
  }
  return s + "</instance_geometry>\n</node>\n";
}

inline std::string light_lib(const std::string& id, const std::string& common, const std::string& cgl_body = "") {
  std::string s = "<library_lights>\n<light id=\"" + id + "\">\n";
  if (!common.empty()) s += "<technique_common>\n" + common + "</technique_common>\n";
  if (!cgl_body.empty()) s += cgl(cgl_body);
  return s + "</light>\n</library_lights>\n";
}
inline std::string light_node(const std::string& url, const std::string& transforms = "") {
  return "<node>\n" + transforms + "<instance_light url=\"" + url + "\"/>\n</node>\n";
}

inline std::string camera_lib(const std::string& id, const std::string& perspective) {
  return "<library_cameras>\n<camera id=\"" + id + "\">\n<optics>\n<technique_common>\n<perspective>\n" + perspective +
         "</perspective>\n</technique_common>\n</optics>\n</camera>\n</library_cameras>\n";
}
inline std::string camera_node(const std::string& url, const std::string& transforms = "") {
  return "<node>\n" + transforms + "<instance_camera url=\"" + url + "\"/>\n</node>\n";
}

// A scene needs geometry or a light to load; this point light is far out of the way.
inline const std::string kFillerLight = light_lib("filler", "<point>\n<color>1 1 1</color>\n</point>\n");
inline const std::string kFillerNode = light_node("#filler");

// ---- the probe: recovering a node's world transform ----

// Images of the origin and of the three unit axes (as vectors) under a world transform.
struct Affine {
  Vec3 o, x, y, z;
  Vec3 apply(Vec3 p) const { return o + x * p.x + y * p.y + z * p.z; }
};
// A triangle mesh whose vertices are the origin and the unit axes (vertex 3 is unreferenced).
inline const std::string kProbeLib = "<library_geometries>\n" +
                              mesh_geometry("probe", "0 0 0  1 0 0  0 1 0  0 0 1", polylist("3", "0 1 2")) +
                              "</library_geometries>\n";
inline Affine affine_of(const MeshDesc& m) {
  EXPECT_EQ(m.positions.size(), 4u);
  if (m.positions.size() != 4) return {};
  Vec3 o = m.positions[0];
  return {o, m.positions[1] - o, m.positions[2] - o, m.positions[3] - o};
}
// The world transform that a node with `transforms` gives under up axis `up`.
inline Affine probe(const std::string& transforms, const std::string& up = "Y_UP") {
  SceneDesc s = parse_collada(dae(geom_node("#probe", transforms), kProbeLib, up), "probe.dae");
  EXPECT_EQ(s.meshes.size(), 1u);
  return s.meshes.empty() ? Affine{} : affine_of(s.meshes[0]);
}

inline ::testing::AssertionResult vec_near(Vec3 a, Vec3 b, float tol = 1e-5f) {
  if (std::fabs(a.x - b.x) <= tol && std::fabs(a.y - b.y) <= tol && std::fabs(a.z - b.z) <= tol)
    return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "(" << a.x << ", " << a.y << ", " << a.z << ") vs expected (" << b.x << ", "
                                       << b.y << ", " << b.z << "), tolerance " << tol;
}

inline ::testing::AssertionResult affine_near(const Affine& a, const Affine& b, float tol = 1e-5f) {
  const char* names[] = {"origin", "x axis", "y axis", "z axis"};
  const Vec3 va[] = {a.o, a.x, a.y, a.z}, vb[] = {b.o, b.x, b.y, b.z};
  for (int i = 0; i < 4; ++i)
    if (auto r = vec_near(va[i], vb[i], tol); !r) return ::testing::AssertionFailure() << names[i] << ": " << r.message();
  return ::testing::AssertionSuccess();
}

inline double mesh_area(const MeshDesc& m) {
  double a = 0;
  for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
    Vec3 p0 = m.positions[m.indices[t]], p1 = m.positions[m.indices[t + 1]], p2 = m.positions[m.indices[t + 2]];
    a += 0.5 * length(cross(p1 - p0, p2 - p0));
  }
  return a;
}

// ---- errors ----

// ":<line>:" for the line on which `marker` first occurs in `text`.
inline std::string line_tag(const std::string& text, const std::string& marker) {
  size_t at = text.find(marker);
  if (at == std::string::npos) return "<marker '" + marker + "' not in the document>";
  return ":" + std::to_string(1 + std::count(text.begin(), text.begin() + at, '\n')) + ":";
}

// Parses `text` as "bad.dae" and succeeds when a SceneError is thrown whose message starts with the
// file name and holds every one of `parts`.
inline ::testing::AssertionResult scene_error(const std::string& text, const std::vector<std::string>& parts,
                                       const LoadLimits& limits = {}) {
  std::string msg;
  try {
    parse_collada(text, "bad.dae", limits);
    return ::testing::AssertionFailure() << "no error was raised";
  } catch (const SceneError& e) {
    msg = e.what();
  } catch (const std::exception& e) {
    return ::testing::AssertionFailure() << "not a SceneError: " << e.what();
  }
  if (msg.rfind("bad.dae", 0) != 0) return ::testing::AssertionFailure() << "message does not start with the file name: " << msg;
  for (const std::string& p : parts)
    if (msg.find(p) == std::string::npos)
      return ::testing::AssertionFailure() << "message lacks '" << p << "': " << msg;
  return ::testing::AssertionSuccess() << msg;
}

// `text` with the first `from` replaced by `to` (the test fails when `from` is absent).
inline std::string with(std::string text, const std::string& from, const std::string& to) {
  size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "'" << from << "' is not in the document";
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// A valid document using most of the dialect, for the malformed-input tests to break one piece at a time.
inline std::string base_doc() {
  std::string libs =
      camera_lib("cam", "<xfov>45</xfov>\n<aspect_ratio>1.5</aspect_ratio>\n<znear>0.1</znear>\n<zfar>100</zfar>\n") +
      light_lib("lamp", "<point>\n<color>1 1 1</color>\n</point>\n", "<area>\n<color>10 10 10</color>\n</area>\n") +
      material("red", phong("phong", "0.8 0.1 0.1 1")) +
      material("glassy", cgl("<glass>\n<reflectance>1 1 1</reflectance>\n<transmittance>1 1 1</transmittance>\n"
                             "<roughness>0</roughness>\n<ior>1.5</ior>\n</glass>\n")) +
      material("metal", cgl("<microfacet>\n<alpha>0.2</alpha>\n<eta>0.2 0.9 1.1</eta>\n<k>3.9 2.4 2.2</k>\n</microfacet>\n")) +
      "<library_geometries>\n" +
      mesh_geometry("quad", "-1 0 -1  1 0 -1  1 0 1  -1 0 1", polylist("3 3", "0 2 1  0 3 2")) +
      sphere_geometry("ball", "0.25") + "</library_geometries>\n" +
      "<library_nodes>\n<node id=\"shared\">\n<translate>0 0.5 0</translate>\n"
      "<instance_geometry url=\"#ball\"/>\n</node>\n</library_nodes>\n";
  std::string nodes = camera_node("#cam", "<translate>0 1 4</translate>\n") +
                      light_node("#lamp", "<translate>0 1.9 0</translate>\n<rotate>1 0 0 90</rotate>\n") +
                      geom_node("#quad", "", {{"red", "#red"}}) +
                      geom_node("#ball", "<translate>-0.5 0.25 0</translate>\n", {{"glassy", "#glassy"}}) +
                      geom_node("#ball", "<translate>0.5 0.25 0</translate>\n", {{"metal", "#metal"}}) +
                      "<node>\n<instance_node url=\"#shared\"/>\n</node>\n";
  return dae(nodes, libs);
}

}  // namespace collada_docs
}  // namespace pt
