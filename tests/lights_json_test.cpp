// LIGHTS.json parsing (tools/io/lights_json.h), CPU only: the values and defaults that reach
// GlintFlareLight, a round trip through to_lights_json, and every kind of bad input, each with a
// one-line message that names the JSON path and the accepted type or range. Hostile input (deep
// nesting, huge arrays, every truncation of a valid file) must end in glint::Error, never a crash.
#include "io/lights_json.h"

#include <glint/glint.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>

namespace glint::io {
namespace {

const std::string kIdentity = "[1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]";

std::string doc(const std::string& lights, const std::string& view_proj = kIdentity) {
  return "{\"view_proj\": " + view_proj + ", \"lights\": [" + lights + "]}";
}

// The message of the Error that parsing `text` throws ("" and a test failure if it does not).
std::string error_of(const std::string& text) {
  try {
    parse_lights_json(text);
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::invalid_argument) << e.what();
    const std::string m = e.what();
    EXPECT_EQ(m.find('\n'), std::string::npos) << "not one line: " << m;
    return m;
  }
  ADD_FAILURE() << "accepted: " << text.substr(0, 200);
  return "";
}

// Expects an error whose message contains every one of `parts`.
void expect_error(const std::string& text, std::initializer_list<const char*> parts) {
  const std::string m = error_of(text);
  for (const char* p : parts)
    EXPECT_NE(m.find(p), std::string::npos) << "message \"" << m << "\" lacks \"" << p << "\"";
}

TEST(LightsJson, ReadsEveryFieldInFileOrder) {
  const std::string text = doc(
      R"({"position": [1.5, -2, 3e2], "color": [0.25, 2, 65504], "intensity": 7, "size": 12.5, "element": "halo", "enabled": false},
         {"position": [0, 0, -1], "element": "STARBURST"},
         {"position": [4, 5, 6], "element": "Ghost", "size": 4096, "intensity": 0},
         {"position": [1, 1, 1], "element": "streak", "color": [0, 0, 0], "enabled": true})",
      "[1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16.25]");
  const LightsFile f = parse_lights_json(text);
  for (int i = 0; i < 16; ++i) EXPECT_EQ(f.view_proj[i], i == 15 ? 16.25f : float(i + 1));
  ASSERT_EQ(f.lights.size(), 4u);
  const GlintFlareLight& a = f.lights[0];
  EXPECT_EQ(a.position_x, 1.5f);
  EXPECT_EQ(a.position_y, -2.0f);
  EXPECT_EQ(a.position_z, 300.0f);
  EXPECT_EQ(a.color_r, 0.25f);
  EXPECT_EQ(a.color_g, 2.0f);
  EXPECT_EQ(a.color_b, 65504.0f);
  EXPECT_EQ(a.intensity, 7.0f);
  EXPECT_EQ(a.size_px, 12.5f);
  EXPECT_EQ(a.element, GLINT_FLARE_ELEMENT_HALO);
  EXPECT_EQ(a.enabled, 0u);
  EXPECT_EQ(a.reserved0, 0u);
  EXPECT_EQ(a.reserved1, 0u);
  // Defaults: colour white, intensity 1, size 100 (kDefaultSizePx), glow, enabled.
  const GlintFlareLight& b = f.lights[1];
  EXPECT_EQ(b.position_z, -1.0f);
  EXPECT_EQ(b.color_r, 1.0f);
  EXPECT_EQ(b.color_g, 1.0f);
  EXPECT_EQ(b.color_b, 1.0f);
  EXPECT_EQ(b.intensity, 1.0f);
  EXPECT_EQ(b.size_px, kDefaultSizePx);
  EXPECT_EQ(b.element, GLINT_FLARE_ELEMENT_STARBURST);
  EXPECT_EQ(b.enabled, 1u);
  EXPECT_EQ(f.lights[2].element, GLINT_FLARE_ELEMENT_GHOST);
  EXPECT_EQ(f.lights[2].size_px, 4096.0f);
  EXPECT_EQ(f.lights[2].intensity, 0.0f);
  EXPECT_EQ(f.lights[3].element, GLINT_FLARE_ELEMENT_STREAK);
  EXPECT_EQ(f.lights[3].enabled, 1u);
  EXPECT_EQ(f.lights[3].color_g, 0.0f);
}

TEST(LightsJson, EmptyLightListAndKeyOrderAreFine) {
  const LightsFile f = parse_lights_json("{\"lights\": [], \"view_proj\": " + kIdentity + "}");
  EXPECT_TRUE(f.lights.empty());
  EXPECT_EQ(f.view_proj[0], 1.0f);
  EXPECT_EQ(f.view_proj[1], 0.0f);
}

TEST(LightsJson, RoundTripKeepsEveryFloat) {
  LightsFile f;
  for (int i = 0; i < 16; ++i) f.view_proj[i] = std::nextafter(0.1f * float(i) - 0.7f, 1.0f);
  const float awkward[] = {0.1f, 1.0f / 3.0f, 1e-30f, 3.4e38f, -0.0f, 123456.789f, 1e-45f};
  uint32_t k = 0;
  for (uint32_t e = 0; e < GLINT_FLARE_ELEMENT_COUNT; ++e) {
    GlintFlareLight l{};
    l.position_x = awkward[k++ % 7];
    l.position_y = -awkward[k++ % 7];
    l.position_z = awkward[k++ % 7] * 0.5f;
    l.color_r = 0.1f * float(e);
    l.color_g = 1.0f / 7.0f;
    l.color_b = 65504.0f;
    l.intensity = 2.0f / 3.0f;
    l.size_px = 0.3f + float(e);
    l.element = e;
    l.enabled = e % 2;
    f.lights.push_back(l);
  }
  const LightsFile back = parse_lights_json(to_lights_json(f));
  EXPECT_EQ(std::memcmp(back.view_proj.data(), f.view_proj.data(), 64), 0);
  ASSERT_EQ(back.lights.size(), f.lights.size());
  EXPECT_EQ(std::memcmp(back.lights.data(), f.lights.data(), f.lights.size() * sizeof(GlintFlareLight)), 0);
  EXPECT_TRUE(parse_lights_json(to_lights_json(LightsFile{})).lights.empty());
}

TEST(LightsJson, MissingKeysNameThePath) {
  expect_error("{\"lights\": []}", {"view_proj", "missing", "16"});
  expect_error("{\"view_proj\": " + kIdentity + "}", {"lights", "missing"});
  expect_error(doc("{\"color\": [1, 1, 1]}"), {"lights[0]", "position", "missing"});
  expect_error(doc("{\"position\": [0, 0, 0]}, {}"), {"lights[1]", "position", "missing"});
}

TEST(LightsJson, WrongTypesNameThePathAndTheExpectedType) {
  expect_error("[]", {"top level", "expected an object", "got an array"});
  expect_error("42", {"top level", "expected an object"});
  expect_error("{\"view_proj\": 1, \"lights\": []}", {"view_proj", "array of 16 numbers", "got a number"});
  expect_error("{\"view_proj\": " + kIdentity + ", \"lights\": {}}",
               {"lights", "array of light objects", "got an object"});
  expect_error(doc("", "[1,0,0,0, 0,1,0,0, 0,0,\"1\",0, 0,0,0,1]"), {"view_proj[10]", "finite number", "got a string"});
  expect_error(doc("3"), {"lights[0]", "light object", "got a number"});
  expect_error(doc("{\"position\": \"0 0 0\"}"), {"lights[0].position", "3 finite numbers", "got a string"});
  expect_error(doc("{\"position\": [0, null, 0]}"), {"lights[0].position[1]", "finite number", "got null"});
  expect_error(doc("{\"position\": [0, 0, 0], \"color\": [1, true, 1]}"),
               {"lights[0].color[1]", "0 to 65504", "got a boolean"});
  expect_error(doc("{\"position\": [0, 0, 0], \"intensity\": \"2\"}"),
               {"lights[0].intensity", "0 to 65504", "got a string"});
  expect_error(doc("{\"position\": [0, 0, 0], \"size\": [3]}"), {"lights[0].size", "pixels", "got an array"});
  expect_error(doc("{\"position\": [0, 0, 0], \"element\": 0}"), {"lights[0].element", "\"glow\"", "got a number"});
  expect_error(doc("{\"position\": [0, 0, 0], \"enabled\": 1}"),
               {"lights[0].enabled", "true or false", "got a number"});
}

TEST(LightsJson, ArrayLengths) {
  expect_error(doc("", "[1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0]"), {"view_proj", "has 15 numbers", "expected 16"});
  expect_error(doc("", "[1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1,0]"), {"view_proj", "more than 16"});
  expect_error(doc("", "[]"), {"view_proj", "has 0 numbers"});
  expect_error(doc("{\"position\": [0, 0]}"), {"lights[0].position", "has 2 numbers", "expected 3"});
  expect_error(doc("{\"position\": [0, 0, 0, 0]}"), {"lights[0].position", "more than 3"});
  expect_error(doc("{\"position\": [0, 0, 0], \"color\": []}"), {"lights[0].color", "has 0 numbers"});
}

TEST(LightsJson, RangesAndNonFiniteNumbers) {
  const std::string p = "{\"position\": [0, 0, 0], ";
  expect_error(doc(p + "\"intensity\": -0.5}"), {"lights[0].intensity", "-0.5", "0 to 65504"});
  expect_error(doc(p + "\"intensity\": 70000}"), {"lights[0].intensity", "0 to 65504"});
  expect_error(doc(p + "\"size\": -3}"), {"lights[0].size", "-3", "> 0 and at most 4096"});
  expect_error(doc(p + "\"size\": 0}"), {"lights[0].size", "> 0"});
  expect_error(doc(p + "\"size\": 4096.5}"), {"lights[0].size", "4096"});
  expect_error(doc(p + "\"color\": [1, -1e-9, 1]}"), {"lights[0].color[1]", "0 to 65504"});
  expect_error(doc(p + "\"color\": [1, 1, 1e39]}"), {"lights[0].color[2]", "0 to 65504"});
  // Beyond float: 1e39 is a fine double but overflows the GPU's float; 1e400 overflows a double.
  expect_error(doc("{\"position\": [0, 1e39, 0]}"), {"lights[0].position[1]", "float range"});
  expect_error(doc("{\"position\": [0, 0, -123456789012345678901234567890123456789012]}"),
               {"lights[0].position[2]", "float range"});
  expect_error(doc("", "[1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,-4e38]"), {"view_proj[15]", "float range"});
  expect_error(doc("{\"position\": [0, 1e400, 0]}"), {"invalid JSON", "lights[0].position[1]", "overflow"});
  expect_error(doc("{\"position\": [0, NaN, 0]}"), {"invalid JSON", "lights[0].position[1]"});
  expect_error(doc("{\"position\": [0, Infinity, 0]}"), {"invalid JSON"});
  // Tiny numbers underflow to 0 (a valid value), -0 is 0.
  const LightsFile f = parse_lights_json(doc("{\"position\": [1e-400, -0, 0], \"intensity\": -0}"));
  EXPECT_EQ(f.lights[0].position_x, 0.0f);
  EXPECT_EQ(f.lights[0].intensity, 0.0f);
}

TEST(LightsJson, UnknownAndDuplicateKeysAndElements) {
  expect_error("{\"view_proj\": " + kIdentity + ", \"lights\": [], \"camera\": 1}",
               {"\"camera\"", "unknown key", "view_proj"});
  expect_error(doc("{\"position\": [0, 0, 0], \"intensty\": 1}"),
               {"lights[0].\"intensty\"", "unknown key", "intensity"});
  expect_error(doc("{\"position\": [0, 0, 0], \"size\": 1, \"size\": 2}"), {"lights[0].\"size\"", "duplicate"});
  expect_error("{\"lights\": [], \"lights\": [], \"view_proj\": " + kIdentity + "}", {"\"lights\"", "duplicate"});
  expect_error(doc("{\"position\": [0, 0, 0], \"element\": \"sparkle\"}"),
               {"lights[0].element", "\"sparkle\"", "ghost"});
  expect_error(doc("{\"position\": [0, 0, 0], \"element\": \"\"}"), {"lights[0].element", "unknown element"});
  // Control characters and invalid UTF-8 in a key are never echoed raw.
  const std::string m = error_of(doc("{\"position\": [0, 0, 0], \"a\\nb\\u0001\": 1}"));
  EXPECT_NE(m.find("\"a?b?\""), std::string::npos) << m;
  error_of(doc("{\"position\": [0, 0, 0], \"element\": \"\xff\xfe\"}"));
}

TEST(LightsJson, MalformedText) {
  expect_error("", {"invalid JSON", "byte"});
  expect_error("   ", {"invalid JSON"});
  expect_error("{", {"invalid JSON"});
  expect_error(doc("{\"position\": [0, 0, 0]},"), {"invalid JSON", "lights"});
  expect_error(doc("") + " x", {"invalid JSON", "end of input"});
  expect_error(doc("") + doc(""), {"invalid JSON"});
  expect_error("{'view_proj': []}", {"invalid JSON"});
  expect_error(std::string("{\"view_proj\"\0: []}", 17), {"invalid JSON"});
  // A whole valid document followed by NUL and garbage: nlohmann's lexer stops at the NUL, so this
  // parsed as the document alone before NUL bytes were rejected.
  expect_error(doc("") + std::string("\0garbage", 8), {"invalid JSON", "NUL byte at offset"});
  expect_error(doc("") + std::string(1, '\0'), {"invalid JSON", "NUL"});
}

// Every prefix of a valid file is an error (never a crash or an accepted half file).
TEST(LightsJson, EveryTruncationIsAnError) {
  const std::string text = doc(
      R"({"position": [1.5, -2, 3], "color": [0.25, 2, 4], "intensity": 7, "size": 12, "element": "halo", "enabled": false})");
  ASSERT_NO_THROW(parse_lights_json(text));
  for (size_t n = 0; n < text.size(); ++n) {
    EXPECT_THROW(parse_lights_json(std::string_view(text.data(), n)), Error) << "prefix of " << n << " bytes";
  }
}

// Hostile input: deep nesting stops at the first wrong type, huge arrays at their limit; both fast.
TEST(LightsJson, HostileInputIsRejectedQuickly) {
  const std::string deep_array(1000000, '[');
  expect_error(deep_array, {"top level", "expected an object"});
  expect_error("{\"lights\": " + std::string(1000000, '['), {"lights[0]", "light object", "got an array"});
  std::string deep_object = "{\"view_proj\": " + kIdentity + ", \"lights\": [";
  for (int i = 0; i < 100000; ++i) deep_object += "{\"position\": ";
  expect_error(deep_object, {"lights[0].position", "got an object"});
  std::string long_matrix = "{\"view_proj\": [";
  for (int i = 0; i < 2000000; ++i) long_matrix += "0,";
  expect_error(long_matrix + "0]}", {"view_proj", "more than 16"});
  expect_error("{\"" + std::string(10000000, 'k') + "\": 1}", {"unknown key", "...\""});
}

// More than kMaxLights lights: rejected with the limit and the reason in the message.
TEST(LightsJson, LightCountIsCapped) {
  const std::string one = "{\"position\":[0,0,0]},";
  std::string lights;
  lights.reserve(one.size() * (kMaxLights + 1));
  for (size_t i = 0; i < kMaxLights; ++i) lights += one;
  std::string at_cap = lights;
  at_cap.pop_back();
  EXPECT_EQ(parse_lights_json(doc(at_cap)).lights.size(), kMaxLights);
  lights += "{\"position\":[0,0,0]}";
  expect_error(doc(lights), {"lights", "more than 1000000"});
}

}  // namespace
}  // namespace glint::io
