// LIGHTS.json through nlohmann::json's SAX interface (json::sax_parse), not its DOM: the schema is
// checked event by event and the parse stops at the first value that breaks it. A DOM would first
// hold the whole document (16 bytes or more per value: "[0,0,0,...]" of 256 MB is 2 GB) and be
// walked afterwards; here deep nesting stops at the first wrong type (the schema is 4 levels deep)
// and arrays stop at their length limit, so memory stays proportional to the accepted lights.
// nlohmann's SAX parser is iterative (no recursion on nesting) and reports errors through
// parse_error() instead of throwing.
#include "io/lights_json.h"

#include <glint/glint.h>

#include <algorithm>
#include <cctype>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <new>
#include <nlohmann/json.hpp>
#include <sstream>

namespace glint::io {
namespace {

using Json = nlohmann::json;

constexpr const char* kElementNames[GLINT_FLARE_ELEMENT_COUNT] = {"glow", "streak", "halo", "starburst", "ghost"};
static_assert(GLINT_FLARE_ELEMENT_GLOW == 0 && GLINT_FLARE_ELEMENT_STREAK == 1 && GLINT_FLARE_ELEMENT_HALO == 2 &&
              GLINT_FLARE_ELEMENT_STARBURST == 3 && GLINT_FLARE_ELEMENT_GHOST == 4);

// Text from the file in a one-line message: at most 40 characters, non-printable bytes as '?'.
std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (size_t i = 0; i < s.size() && i < 40; ++i) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    out += (c >= 0x20 && c < 0x7F) ? static_cast<char>(c) : '?';
  }
  if (s.size() > 40) out += "...";
  return out + "\"";
}

std::string number_text(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

// What a JSON value is, for the type check.
enum class Kind { null, boolean, number, string, object, array };

const char* kind_name(Kind k) {
  switch (k) {
    case Kind::null:
      return "null";
    case Kind::boolean:
      return "a boolean";
    case Kind::number:
      return "a number";
    case Kind::string:
      return "a string";
    case Kind::object:
      return "an object";
    case Kind::array:
      return "an array";
  }
  return "a value";
}

// Keys of a light object, as bits of Frame::seen.
enum LightKey : uint32_t { kPosition = 1, kColor = 2, kIntensity = 4, kSize = 8, kElement = 16, kEnabled = 32 };

struct LightKeyInfo {
  const char* name;
  LightKey bit;
  Kind kind;
  const char* expected;  // for type errors
};
constexpr LightKeyInfo kLightKeys[] = {
    {"position", kPosition, Kind::array, "an array of 3 finite numbers [x, y, z]"},
    {"color", kColor, Kind::array, "an array of 3 numbers [r, g, b], each 0 to 65504"},
    {"intensity", kIntensity, Kind::number, "a number from 0 to 65504"},
    {"size", kSize, Kind::number, "a number of pixels, > 0 and at most 4096"},
    {"element", kElement, Kind::string, "one of \"glow\", \"streak\", \"halo\", \"starburst\", \"ghost\""},
    {"enabled", kEnabled, Kind::boolean, "true or false"},
};

class Handler final : public nlohmann::json_sax<Json> {
 public:
  LightsFile result;
  std::string error;  // set when a callback returned false

  bool null() override { return value(Kind::null); }
  bool boolean(bool v) override { return value(Kind::boolean, 0.0, nullptr, v); }
  bool number_integer(number_integer_t v) override { return value(Kind::number, static_cast<double>(v)); }
  bool number_unsigned(number_unsigned_t v) override { return value(Kind::number, static_cast<double>(v)); }
  bool number_float(number_float_t v, const string_t&) override { return value(Kind::number, v); }
  bool string(string_t& v) override { return value(Kind::string, 0.0, &v); }
  bool binary(binary_t&) override { return fail(value_path() + ": binary values are not JSON"); }

  bool start_object(std::size_t) override {
    if (!value(Kind::object)) return false;
    stack_.push_back(stack_.empty() ? Frame{Frame::top} : Frame{Frame::light});
    if (stack_.back().type == Frame::light) result.lights.push_back(default_light());
    return true;
  }
  bool key(string_t& k) override {
    Frame& f = stack_.back();
    uint32_t bit = 0;
    if (f.type == Frame::top) {
      bit = k == "view_proj" ? 1u : k == "lights" ? 2u : 0u;
      if (!bit) return fail(where(k) + ": unknown key; accepted keys: \"view_proj\", \"lights\"");
    } else {
      for (const auto& info : kLightKeys) {
        if (k == info.name) bit = info.bit;
      }
      if (!bit) {
        return fail(where(k) +
                    ": unknown key; accepted keys: \"position\", \"color\", \"intensity\", \"size\", "
                    "\"element\", \"enabled\"");
      }
    }
    if (f.seen & bit) return fail(where(k) + ": duplicate key");
    f.seen |= bit;
    f.key = k;
    return true;
  }
  bool end_object() override {
    const Frame f = stack_.back();
    const std::string name = container_path();
    stack_.pop_back();
    if (f.type == Frame::top) {
      if (!(f.seen & 1u)) return fail("view_proj: missing; expected an array of 16 numbers (column-major)");
      if (!(f.seen & 2u)) return fail("lights: missing; expected an array of light objects (may be empty)");
      return true;
    }
    if (!(f.seen & kPosition)) {
      return fail(name + ": \"position\" is missing; expected an array of 3 finite numbers [x, y, z]");
    }
    return true;
  }
  bool start_array(std::size_t) override {
    if (!value(Kind::array)) return false;
    const Frame& parent = stack_.back();
    if (parent.type == Frame::top) {
      stack_.push_back(Frame{parent.key == "view_proj" ? Frame::view_proj : Frame::lights});
    } else {
      stack_.push_back(Frame{parent.key == "position" ? Frame::position : Frame::color});
    }
    return true;
  }
  bool end_array() override {
    const Frame f = stack_.back();
    const std::string name = container_path();
    stack_.pop_back();
    if (f.type == Frame::view_proj && f.count != 16) {
      return fail("view_proj: has " + std::to_string(f.count) + " numbers; expected 16 (a column-major 4x4 matrix)");
    }
    if ((f.type == Frame::position || f.type == Frame::color) && f.count != 3) {
      return fail(name + ": has " + std::to_string(f.count) + " numbers; expected 3");
    }
    return true;
  }
  bool parse_error(std::size_t position, const std::string&, const nlohmann::detail::exception& e) override {
    // nlohmann's message starts with "[json.exception.parse_error.101] "; keep what follows.
    std::string what = e.what();
    const size_t bracket = what.find("] ");
    if (what.rfind("[json.exception.", 0) == 0 && bracket != std::string::npos) what.erase(0, bracket + 2);
    std::string near = stack_.empty() ? std::string() : " (in " + value_path() + ")";
    return fail("invalid JSON at byte " + std::to_string(position) + near + ": " + what);
  }

 private:
  struct Frame {
    enum Type { top, view_proj, lights, light, position, color } type;
    size_t count = 0;   // arrays: values seen so far
    uint32_t seen = 0;  // objects: keys seen (bits)
    std::string key;    // objects: the key whose value comes next
  };
  std::vector<Frame> stack_;

  bool fail(const std::string& message) {
    if (error.empty()) error = message;
    return false;
  }

  static GlintFlareLight default_light() {
    GlintFlareLight l{};
    l.color_r = l.color_g = l.color_b = 1.0f;
    l.intensity = 1.0f;
    l.size_px = kDefaultSizePx;
    l.element = GLINT_FLARE_ELEMENT_GLOW;
    l.enabled = 1;
    return l;
  }

  // One step of a JSON path: ".key" (or "key" first) for objects, "[i]" for arrays; `next` names
  // the array slot about to be filled instead of the last one filled.
  static std::string selector(const Frame& f, bool first, bool next) {
    std::string s;
    if (f.type == Frame::top || f.type == Frame::light) {
      if (!first) s += '.';
      s += f.key;
    } else {
      s += '[';
      s += std::to_string(next ? f.count : f.count - 1);
      s += ']';
    }
    return s;
  }
  // The path of the innermost open container ("lights[3]", "lights[3].position"; "" at the top).
  std::string container_path() const {
    std::string p;
    for (size_t i = 0; i + 1 < stack_.size(); ++i) p += selector(stack_[i], i == 0, false);
    return p;
  }
  // The path of the value being parsed now ("lights[3].size", "view_proj[16]").
  std::string value_path() const {
    std::string p;
    for (size_t i = 0; i < stack_.size(); ++i) p += selector(stack_[i], i == 0, i + 1 == stack_.size());
    return p.empty() ? "(top level)" : p;
  }
  std::string where(const std::string& key) const {
    const std::string parent = container_path();
    return parent.empty() ? quoted(key) : parent + "." + quoted(key);
  }

  // Checks the type of a value at the current position, then stores numbers, strings and booleans.
  bool value(Kind kind, double number = 0.0, const std::string* text = nullptr, bool flag = false) {
    if (stack_.empty()) {
      if (kind != Kind::object) {
        return fail(std::string("(top level): expected an object {\"view_proj\": [...], \"lights\": [...]}, got ") +
                    kind_name(kind));
      }
      return true;
    }
    Frame& f = stack_.back();
    const std::string here = value_path();
    auto wrong = [&](const char* expected) {
      return fail(here + ": expected " + std::string(expected) + ", got " + kind_name(kind));
    };
    switch (f.type) {
      case Frame::top:
        if (kind != Kind::array) {
          return wrong(f.key == "view_proj" ? "an array of 16 numbers (column-major)" : "an array of light objects");
        }
        return true;
      case Frame::view_proj:
        if (f.count >= 16) return fail("view_proj: has more than 16 numbers; expected 16 (a column-major 4x4 matrix)");
        if (kind != Kind::number) return wrong("a finite number");
        if (!check_float(here, number, "a finite number within float range")) return false;
        result.view_proj[f.count++] = static_cast<float>(number);
        return true;
      case Frame::lights:
        if (f.count >= kMaxLights) {
          return fail("lights: more than " + std::to_string(kMaxLights) +
                      " lights; glint flare reads at most that many (48 MB of light and instance buffers)");
        }
        ++f.count;
        if (kind != Kind::object) return wrong("a light object {\"position\": [x, y, z], ...}");
        return true;
      case Frame::position:
      case Frame::color: {
        const bool position = f.type == Frame::position;
        if (f.count >= 3) {
          return fail(container_path() + ": has more than 3 numbers; expected 3");
        }
        if (kind != Kind::number) return wrong(position ? "a finite number" : "a number from 0 to 65504");
        GlintFlareLight& l = result.lights.back();
        if (position) {
          if (!check_float(here, number, "a finite number within float range")) return false;
          (&l.position_x)[f.count++] = static_cast<float>(number);
        } else {
          if (!check_range(here, number, 0.0, kMaxColor, false, "0 to 65504")) return false;
          (&l.color_r)[f.count++] = static_cast<float>(number);
        }
        return true;
      }
      case Frame::light: {
        const LightKeyInfo* info = nullptr;
        for (const auto& k : kLightKeys) {
          if (f.key == k.name) info = &k;
        }
        if (kind != info->kind) return wrong(info->expected);
        GlintFlareLight& l = result.lights.back();
        switch (info->bit) {
          case kIntensity:
            if (!check_range(here, number, 0.0, kMaxColor, false, "0 to 65504")) return false;
            l.intensity = static_cast<float>(number);
            return true;
          case kSize:
            if (!check_range(here, number, 0.0, kMaxSizePx, true, "> 0 and at most 4096 pixels")) return false;
            l.size_px = static_cast<float>(number);
            return true;
          case kEnabled:
            l.enabled = flag ? 1u : 0u;
            return true;
          case kElement: {
            std::string lower = *text;
            std::transform(lower.begin(), lower.end(), lower.begin(),
                           [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
            for (uint32_t e = 0; e < GLINT_FLARE_ELEMENT_COUNT; ++e) {
              if (lower == kElementNames[e]) {
                l.element = e;
                return true;
              }
            }
            return fail(here + ": unknown element " + quoted(*text) + "; accepted " + info->expected);
          }
          default:
            return true;  // arrays: start_array pushes the frame
        }
      }
    }
    return true;
  }

  bool check_float(const std::string& here, double v, const char* accepted) {
    if (!std::isfinite(v) || std::fabs(v) > double(FLT_MAX)) {
      return fail(here + ": " + number_text(v) + " is out of range; accepted " + accepted);
    }
    return true;
  }
  bool check_range(const std::string& here, double v, double lo, double hi, bool lo_exclusive, const char* accepted) {
    const bool ok = std::isfinite(v) && (lo_exclusive ? v > lo : v >= lo) && v <= hi;
    if (!ok) return fail(here + ": " + number_text(v) + " is out of range; accepted " + accepted);
    return true;
  }
};

}  // namespace

const char* flare_element_name(uint32_t element) {
  return element < GLINT_FLARE_ELEMENT_COUNT ? kElementNames[element] : kElementNames[0];
}

LightsFile parse_lights_json(std::string_view text) {
  // nlohmann's lexer takes a NUL byte for the end of the input (for C strings), so "{...}\0garbage"
  // would parse as the object alone. JSON text has no NUL anywhere (RFC 8259: control characters
  // are not allowed unescaped, even in strings), so any NUL is an error.
  if (const size_t nul = text.find('\0'); nul != std::string_view::npos) {
    throw Error(ErrorCode::invalid_argument,
                "invalid JSON: NUL byte at offset " + std::to_string(nul) + " (JSON text cannot contain NUL)");
  }
  Handler handler;
  bool ok = false;
  try {
    ok = Json::sax_parse(text.begin(), text.end(), &handler, Json::input_format_t::json, /*strict=*/true);
  } catch (const std::bad_alloc&) {
    throw Error(ErrorCode::invalid_argument, "out of memory while parsing the light list");
  } catch (const std::exception& e) {  // not expected: SAX reports errors through parse_error()
    throw Error(ErrorCode::invalid_argument, std::string("invalid JSON: ") + e.what());
  }
  if (!ok) throw Error(ErrorCode::invalid_argument, handler.error.empty() ? "invalid JSON" : handler.error);
  return std::move(handler.result);
}

LightsFile load_lights_json(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (!fs::exists(st)) throw Error(ErrorCode::io_failure, path + ": no such file");
  if (fs::is_directory(st)) throw Error(ErrorCode::io_failure, path + ": is a directory, not a JSON file");
  const auto bytes = fs::file_size(path, ec);
  if (ec) throw Error(ErrorCode::io_failure, path + ": cannot access: " + ec.message());
  if (bytes > kMaxLightsFileBytes) {
    throw Error(ErrorCode::invalid_argument, path + ": " + std::to_string(bytes) + " bytes; glint reads at most " +
                                                 std::to_string(kMaxLightsFileBytes) + " bytes of LIGHTS.json");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(ErrorCode::io_failure, path + ": cannot open for reading");
  std::string text(static_cast<size_t>(bytes), '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  if (static_cast<size_t>(in.gcount()) != text.size()) throw Error(ErrorCode::io_failure, path + ": read failed");
  try {
    return parse_lights_json(text);
  } catch (const Error& e) {
    throw Error(e.code(), path + ": " + e.what());
  }
}

std::string to_lights_json(const LightsFile& file) {
  // Written by hand, one light per line: nlohmann's dump() writes doubles in shortest round-trip
  // form, which we keep by going through Json for each number.
  auto num = [](float v) { return Json(static_cast<double>(v)).dump(); };
  std::ostringstream out;
  out << "{\"view_proj\": [";
  for (size_t i = 0; i < 16; ++i) out << (i ? ", " : "") << num(file.view_proj[i]);
  out << "],\n \"lights\": [";
  for (size_t i = 0; i < file.lights.size(); ++i) {
    const GlintFlareLight& l = file.lights[i];
    out << (i ? ",\n  " : "\n  ") << "{\"position\": [" << num(l.position_x) << ", " << num(l.position_y) << ", "
        << num(l.position_z) << "], \"color\": [" << num(l.color_r) << ", " << num(l.color_g) << ", " << num(l.color_b)
        << "], \"intensity\": " << num(l.intensity) << ", \"size\": " << num(l.size_px) << ", \"element\": \""
        << flare_element_name(l.element) << "\", \"enabled\": " << (l.enabled ? "true" : "false") << "}";
  }
  out << (file.lights.empty() ? "]}\n" : "\n ]}\n");
  return out.str();
}

}  // namespace glint::io
