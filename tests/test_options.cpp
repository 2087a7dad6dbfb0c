// The one table of render options (renderer/options.h) against everything made from it or checked
// by it: RenderParams' own defaults, the CLI's ranges, RenderParams::validate, the job service's
// JSON fields, and the OpenAPI document's job fields (server/openapi.json). Each test fails when
// one of them drifts from the table.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <set>

#include "cli.h"
#include "job_spec.h"
#include "options.h"

using pt::OptionType;
using pt::RenderOption;

namespace {

// A value's text as a user types it: integers without a fraction, others with full precision.
std::string typed(const RenderOption& o, double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, o.type == OptionType::integer ? "%.0f" : "%.17g", v);
  return buf;
}

// The CLI arguments that give option `o` the value `v` (with -r and -a, the other value valid).
std::vector<std::string> cli_args(const RenderOption& o, double v) {
  std::string flag = o.flag, name = o.name;
  std::vector<std::string> args;
  if (flag == "-r") args = {"-r", name == "width" ? typed(o, v) : "8", name == "height" ? typed(o, v) : "8"};
  else if (flag == "-a") args = {"-a", name == "adaptive_batch" ? typed(o, v) : "4", name == "adaptive_tolerance" ? typed(o, v) : "0.1"};
  else args = {flag, typed(o, v)};
  args.push_back("scene.dae");
  return args;
}

double value_after_cli(const RenderOption& o, const std::vector<std::string>& args) {
  pt::CliOptions c = pt::parse_cli(args);
  return o.get(c.params, c.limits);
}

nlohmann::json openapi() {
  std::ifstream in(std::string(PT_OWN_SCENES) + "/../server/openapi.json");
  return nlohmann::json::parse(in);
}

}  // namespace

TEST(Options, TheCourseColumnIsWhatRenderParamsAndRunLimitsDefaultTo) {
  std::set<std::string> names, keys;
  for (const RenderOption& o : pt::render_options()) {
    EXPECT_EQ(o.get(pt::RenderParams(), pt::RunLimits()), o.type == OptionType::real ? double(float(o.course)) : o.course)
        << o.name;
    EXPECT_LE(o.min, o.course) << o.name;
    EXPECT_LE(o.course, o.max) << o.name;
    EXPECT_TRUE(names.insert(o.name).second) << "two options named " << o.name;
    EXPECT_TRUE(keys.insert(o.metadata).second) << "two options write " << o.metadata;
    EXPECT_EQ(std::string(o.metadata).rfind("pathtracer:", 0), 0u) << o.metadata;
  }
}

TEST(Options, TheCliTakesEachRangeWholeAndNothingBeyond) {
  for (const RenderOption& o : pt::render_options()) {
    if (o.type == OptionType::boolean || std::string(o.flag).empty()) continue;
    EXPECT_EQ(value_after_cli(o, cli_args(o, o.min)), o.type == OptionType::real ? double(float(o.min)) : o.min) << o.name;
    EXPECT_EQ(value_after_cli(o, cli_args(o, o.max)), o.type == OptionType::real ? double(float(o.max)) : o.max) << o.name;
    // One past the range (for a seed of 2^53, a step a double can still tell apart).
    double step = o.type == OptionType::integer ? std::max(1.0, std::ceil(o.max * 1e-12)) : std::max(1e-3, o.max * 1e-3);
    EXPECT_THROW(pt::parse_cli(cli_args(o, o.max + step)), pt::UsageError) << o.name;
    EXPECT_THROW(pt::parse_cli(cli_args(o, o.min - step)), pt::UsageError) << o.name;
  }
}

TEST(Options, ValidateRefusesEachOptionOutsideItsRangeByName) {
  for (const RenderOption& o : pt::render_options()) {
    if (o.type == OptionType::boolean || o.name == std::string("time_limit") || o.name == std::string("target_error"))
      continue;
    pt::RenderParams p;
    pt::RunLimits l;
    o.set(p, l, o.max);
    EXPECT_NO_THROW(p.validate()) << o.name;
    if (o.name == std::string("seed")) continue;  // unsigned: nothing below 0 to set
    o.set(p, l, o.min - 1);
    try {
      p.validate();
      ADD_FAILURE() << o.name << " below its range passed";
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()).rfind(o.name, 0), 0u) << e.what();
    }
  }
}

TEST(Options, JobFieldsAreTheTableNarrowedByTheServersPolicy) {
  srv::SpecLimits lim;
  srv::json defaults = srv::job_spec_defaults();
  std::set<std::string> fields;
  for (auto it = defaults.begin(); it != defaults.end(); ++it)
    if (it.key() != "denoise") fields.insert(it.key());  // a choice of the service's, not a render option
  EXPECT_EQ(fields.size(), pt::render_options().size());
  EXPECT_EQ(defaults["denoise"], "off");
  for (const RenderOption& o : pt::render_options()) {
    ASSERT_TRUE(defaults.contains(o.name)) << o.name;
    if (o.type == OptionType::boolean) EXPECT_EQ(defaults[o.name].get<bool>(), o.service != 0) << o.name;
    else EXPECT_EQ(defaults[o.name].get<double>(), double(float(o.service)) == o.service || o.type != OptionType::real
                                                      ? o.service
                                                      : std::strtod(pt::option_text(o, o.service).c_str(), nullptr))
        << o.name;
    auto [lo, hi] = srv::job_range(o, lim);
    EXPECT_GE(lo, o.min) << o.name;
    EXPECT_LE(hi, o.max) << o.name;
    if (o.type == OptionType::boolean) continue;
    srv::json at_hi{{"scene", "s"}, {o.name, hi}}, over{{"scene", "s"}, {o.name, hi + (o.type == OptionType::integer ? 1 : hi * 1e-3 + 1e-3)}};
    if (o.type == OptionType::integer) {
      at_hi[o.name] = (long long)hi;
      over[o.name] = (long long)hi + 1;
    }
    // spp at the top of its range would pass the pixel-sample cap only on a small image.
    if (o.name == std::string("spp")) at_hi["width"] = at_hi["height"] = 8;
    EXPECT_NO_THROW(srv::parse_job_spec(at_hi, lim)) << o.name;
    try {
      srv::parse_job_spec(over, lim);
      ADD_FAILURE() << o.name << " over its job range passed";
    } catch (const srv::JobError& e) {
      EXPECT_EQ(e.field(), o.name);
    }
  }
}

TEST(Options, TheOpenApiJobFieldsMatchTheTable) {
  srv::json doc = openapi();
  srv::SpecLimits lim;
  for (const char* schema : {"JobSpec", "JobSpecNormalised", "SpecDefaults"}) {
    const srv::json& props = doc["components"]["schemas"][schema]["properties"];
    std::set<std::string> documented;
    for (auto it = props.begin(); it != props.end(); ++it)
      // The camera is a pose, not an option of the table (camera.h); denoise is the service's choice.
      if (it.key() != "scene" && it.key() != "camera" && it.key() != "denoise") documented.insert(it.key());
    EXPECT_EQ(documented.size(), pt::render_options().size()) << schema;
    for (const RenderOption& o : pt::render_options()) {
      SCOPED_TRACE(std::string(schema) + "." + o.name);
      ASSERT_TRUE(props.contains(o.name));
      const srv::json& f = props[o.name];
      const char* type = o.type == OptionType::boolean ? "boolean" : o.type == OptionType::integer ? "integer" : "number";
      EXPECT_EQ(f["type"], type);
      if (o.type != OptionType::boolean) {
        auto [lo, hi] = srv::job_range(o, lim);
        EXPECT_EQ(f["minimum"].get<double>(), lo);
        EXPECT_EQ(f["maximum"].get<double>(), hi);
      }
      if (std::string(schema) == "JobSpec") {
        ASSERT_TRUE(f.contains("default"));
        if (o.type == OptionType::boolean) EXPECT_EQ(f["default"].get<bool>(), o.service != 0);
        else EXPECT_NEAR(f["default"].get<double>(), o.service, 1e-12 * std::max(1.0, o.service));
      }
    }
  }
}
