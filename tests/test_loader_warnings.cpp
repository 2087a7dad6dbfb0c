// What the COLLADA loader ignores or defaults is said, one line each naming the file, the line and
// the element, in SceneDesc::warnings (which the job service shows) and on stderr; a valid scene
// that uses nothing unsupported loads without a warning.
#include <gtest/gtest.h>

#include "collada.h"
#include "collada_docs.h"

using namespace pt;
using namespace pt::collada_docs;

namespace {

std::vector<std::string> warnings_of(const std::string& doc) {
  ::testing::internal::CaptureStderr();
  SceneDesc d = parse_collada(doc, "w.dae");
  const std::string err = ::testing::internal::GetCapturedStderr();
  for (const std::string& w : d.warnings) EXPECT_NE(err.find("warning: " + w), std::string::npos) << w << " not printed";
  return d.warnings;
}

// The one warning `doc` gets, which must name `element` and say `what`.
void expect_one_warning(const std::string& doc, const std::string& element, const std::string& what) {
  const std::vector<std::string> w = warnings_of(doc);
  ASSERT_EQ(w.size(), 1u) << ::testing::PrintToString(w);
  EXPECT_EQ(w[0].rfind("w.dae:", 0), 0u) << w[0];
  EXPECT_NE(w[0].find(element), std::string::npos) << w[0];
  EXPECT_NE(w[0].find(what), std::string::npos) << w[0];
}

}  // namespace

TEST(LoaderWarnings, AValidSceneLoadsWithoutAny) { EXPECT_TRUE(warnings_of(base_doc()).empty()); }

TEST(LoaderWarnings, AnEffectWeCannotReadIsRenderedGreyAndSaidSo) {
  expect_one_warning(with(with(base_doc(), "<profile_COMMON>", "<profile_GLSL>"), "</profile_COMMON>", "</profile_GLSL>"),
                     "<effect id='red-fx'>", "default 0.5 grey");
  expect_one_warning(with(base_doc(), "<color sid=\"diffuse\">0.8 0.1 0.1 1</color>", "<texture texture=\"img\"/>"),
                     "<diffuse>", "texture is not read");
  expect_one_warning(with(base_doc(), "<glass>\n", "<sparkle/>\n<glass>\n"), "<sparkle>", "not a CGL material");
}

TEST(LoaderWarnings, AMissingCameraIsSaid) {
  expect_one_warning(with(base_doc(), camera_node("#cam", "<translate>0 1 4</translate>\n"), ""), "<visual_scene",
                     "no <instance_camera>");
}

TEST(LoaderWarnings, DuplicateIdsAreSaidAndTheFirstIsReached) {
  const std::string doc = with(base_doc(), "</library_nodes>\n",
                               "</library_nodes>\n<library_images>\n<image id=\"red\"/>\n</library_images>\n");
  expect_one_warning(doc, "<image id='red'>", "duplicate id 'red'");
  SceneDesc d = parse_collada(doc, "w.dae");  // the material, first in the document, is what binds
  EXPECT_NEAR(d.materials[d.meshes[0].tri_material[0]].albedo.x, 0.8f, 1e-6f);
}

TEST(LoaderWarnings, ACountThatDisagreesWithTheDataIsSaidAndTheDataUsed) {
  const std::string doc = with(base_doc(), "<polylist count=\"2\"", "<polylist count=\"5\"");
  expect_one_warning(doc, "<polylist>", "count says 5 but the data holds 2");
  EXPECT_EQ(parse_collada(doc, "w.dae").triangle_count(), 2u);
}

TEST(LoaderWarnings, PartsWeSkipAreSaidOnce) {
  expect_one_warning(with(base_doc(), "</library_nodes>\n",
                          "</library_nodes>\n<library_animations>\n<animation id=\"spin\"/>\n</library_animations>\n"),
                     "<library_animations>", "animations are not rendered");
  expect_one_warning(with(base_doc(), "<instance_node url=\"#shared\"/>", "<instance_controller url=\"#skin\"/>"),
                     "<instance_controller>", "not rendered");
  expect_one_warning(with(base_doc(), "<polylist count=\"2\"", "<polylist material=\"blue\" count=\"2\""),
                     "<polylist>", "material symbol 'blue' is not bound");
}
