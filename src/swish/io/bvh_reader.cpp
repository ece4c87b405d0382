#include "swish/io/bvh_reader.hpp"

#include <cmath>
#include <fstream>
#include <sstream>

#include "swish/core/error.hpp"

namespace swish::io {
namespace {

enum class Channel { Xpos, Ypos, Zpos, Xrot, Yrot, Zrot };

// Whitespace-separated tokens with the line each came from.
class Tokens {
 public:
  Tokens(std::istream& in, std::string name) : in_(in), name_(std::move(name)) {}

  bool next(std::string& tok) {
    while (!(line_ >> tok)) {
      std::string text;
      if (!std::getline(in_, text)) return false;
      ++lineNo_;
      line_.clear();
      line_.str(text);
    }
    return true;
  }
  std::string expectAny(const char* what) {
    std::string t;
    if (!next(t)) fail(std::string("file ends where ") + what + " was expected");
    return t;
  }
  void expect(const std::string& word) {
    const std::string t = expectAny(("'" + word + "'").c_str());
    if (t != word) fail("expected '" + word + "', found '" + t + "'");
  }
  double number(const char* what) {
    const std::string t = expectAny(what);
    char* end = nullptr;
    const double v = std::strtod(t.c_str(), &end);
    if (end == t.c_str() || *end != '\0') fail(std::string("expected a number for ") + what + ", found '" + t + "'");
    if (!std::isfinite(v)) fail(std::string("non-finite value '") + t + "' for " + what);
    return v;
  }
  // The rest of the current line, for "Frame Time:" style headers.
  [[noreturn]] void fail(const std::string& why) const {
    throw Error(name_ + ":" + std::to_string(lineNo_) + ": " + why);
  }
  int line() const { return lineNo_; }

 private:
  std::istream& in_;
  std::string name_;
  std::istringstream line_;
  int lineNo_ = 0;
};

Quatf axisRotation(Channel c, double degrees) {
  const float rad = float(degrees * M_PI / 180.0);
  const Vec3f axis = c == Channel::Xrot ? Vec3f::UnitX() : c == Channel::Yrot ? Vec3f::UnitY() : Vec3f::UnitZ();
  return Quatf(Eigen::AngleAxisf(rad, axis));
}

}  // namespace

SourceAnimation readBvh(std::istream& in, const std::string& name) {
  Tokens tok(in, name);
  SourceAnimation anim;
  anim.name = std::filesystem::path(name).stem().string();
  std::vector<std::vector<Channel>> channels;

  tok.expect("HIERARCHY");
  std::string t = tok.expectAny("'ROOT'");
  if (t != "ROOT") tok.fail("expected 'ROOT', found '" + t + "'");
  // Recursive descent over ROOT/JOINT/End Site blocks with an explicit stack of open joints.
  std::vector<int> open;  // joint index per open brace, -1 for an End Site
  auto beginJoint = [&](int parent) {
    const std::string jname = tok.expectAny("a joint name");
    if (anim.find(jname) >= 0) tok.fail("joint name '" + jname + "' repeats");
    tok.expect("{");
    tok.expect("OFFSET");
    RigidTransform rest;
    for (int k = 0; k < 3; ++k) rest.translation[k] = float(tok.number("an OFFSET component"));
    tok.expect("CHANNELS");
    const double n = tok.number("the channel count");
    if (n < 0 || n > 6 || n != std::floor(n)) tok.fail("channel count must be 0 to 6");
    std::vector<Channel> ch;
    for (int k = 0; k < int(n); ++k) {
      const std::string c = tok.expectAny("a channel name");
      if (c == "Xposition")
        ch.push_back(Channel::Xpos);
      else if (c == "Yposition")
        ch.push_back(Channel::Ypos);
      else if (c == "Zposition")
        ch.push_back(Channel::Zpos);
      else if (c == "Xrotation")
        ch.push_back(Channel::Xrot);
      else if (c == "Yrotation")
        ch.push_back(Channel::Yrot);
      else if (c == "Zrotation")
        ch.push_back(Channel::Zrot);
      else
        tok.fail("unknown channel '" + c + "'");
    }
    anim.jointNames.push_back(jname);
    anim.parents.push_back(parent);
    anim.rest.push_back(rest);
    channels.push_back(std::move(ch));
    open.push_back(int(anim.jointNames.size()) - 1);
  };
  beginJoint(-1);
  while (!open.empty()) {
    t = tok.expectAny("'JOINT', 'End Site' or '}'");
    if (t == "}") {
      open.pop_back();
    } else if (t == "JOINT") {
      if (open.back() < 0) tok.fail("a JOINT inside an End Site");
      beginJoint(open.back());
    } else if (t == "End") {
      tok.expect("Site");
      tok.expect("{");
      tok.expect("OFFSET");
      for (int k = 0; k < 3; ++k) tok.number("an End Site OFFSET component");
      tok.expect("}");
    } else {
      tok.fail("expected 'JOINT', 'End Site' or '}', found '" + t + "'");
    }
  }
  tok.expect("MOTION");
  tok.expect("Frames:");
  const double frames = tok.number("the frame count");
  if (frames < 1 || frames != std::floor(frames) || frames > 1e7) tok.fail("frame count must be a positive integer");
  tok.expect("Frame");
  tok.expect("Time:");
  const double frameTime = tok.number("the frame time");
  if (!(frameTime > 0)) tok.fail("frame time must be positive");
  anim.framesPerSecond = 1.0 / frameTime;

  anim.frames.resize(size_t(frames));
  for (size_t f = 0; f < anim.frames.size(); ++f) {
    auto& locals = anim.frames[f];
    locals.resize(anim.jointCount());
    for (size_t j = 0; j < anim.jointCount(); ++j) {
      RigidTransform x = anim.rest[j];
      for (Channel c : channels[j]) {
        std::string tokText;
        if (!tok.next(tokText))
          tok.fail("file ends in frame " + std::to_string(f) + " of " + std::to_string(anim.frames.size()) +
                   " (truncated motion data)");
        char* end = nullptr;
        const double v = std::strtod(tokText.c_str(), &end);
        if (end == tokText.c_str() || *end != '\0')
          tok.fail("frame " + std::to_string(f) + ", joint '" + anim.jointNames[j] + "': expected a number, found '" +
                   tokText + "'");
        if (!std::isfinite(v))
          tok.fail("frame " + std::to_string(f) + ", joint '" + anim.jointNames[j] + "': non-finite value '" + tokText +
                   "'");
        switch (c) {
          case Channel::Xpos:
            x.translation.x() = float(v);
            break;
          case Channel::Ypos:
            x.translation.y() = float(v);
            break;
          case Channel::Zpos:
            x.translation.z() = float(v);
            break;
          default:
            x.rotation = x.rotation * axisRotation(c, v);
            break;
        }
      }
      x.rotation.normalize();
      locals[j] = x;
    }
  }
  std::string extra;
  if (tok.next(extra))
    tok.fail("unexpected data after the " + std::to_string(anim.frames.size()) + " declared frames: '" + extra + "'");
  return anim;
}

SourceAnimation readBvh(const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) throw Error(file.string() + ": no such file");
  std::ifstream in(file);
  if (!in) throw Error(file.string() + ": cannot open");
  return readBvh(in, file.string());
}

}  // namespace swish::io
