#include "conformance/external.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <nlohmann/json.hpp>

#include "backends/oracle/oracle.hpp"
#include "interop/peer_import.hpp"
#include "kernels/camera.hpp"
#include "output/image_io.hpp"
#include "scene/load.hpp"

extern char** environ;

namespace flatmarch::conformance {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

const std::vector<std::string> kChannels = {"colour", "hit", "crossings", "steps", "t"};
const std::vector<std::string> kLooks = {"flatmarch", "peer-app", "none"};
const std::vector<std::string> kParameters = {"eps", "offset", "max_steps", "max_distance",
                                              "omega"};
const std::vector<std::string> kFormats = {"flatmarch", "peer-app"};

bool among(const std::vector<std::string>& list, const std::string& s) {
  return std::find(list.begin(), list.end(), s) != list.end();
}

std::string joined(const std::vector<std::string>& list) {
  std::string s;
  for (const std::string& e : list) s += (s.empty() ? "" : ", ") + e;
  return s;
}

std::string read_text(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// A program named without a folder, looked up on PATH as the shell would; empty if not there.
std::string on_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::istringstream folders(path ? path : "/usr/bin:/bin");
  for (std::string folder; std::getline(folders, folder, ':');) {
    const fs::path candidate = fs::path(folder.empty() ? "." : folder) / program;
    if (access(candidate.c_str(), X_OK) == 0) return candidate.string();
  }
  return {};
}

// The path of this program, for the renderer's $FLATMARCH.
std::string self_path() {
  std::error_code error;
  const fs::path self = fs::read_symlink("/proc/self/exe", error);
  return error ? std::string() : self.string();
}

// The last `n` non-empty lines of a text, joined by " | ".
std::string last_lines(const std::string& text, size_t n) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) lines.push_back(line);
  std::string out;
  constexpr size_t kWidth = 240;  // a line's characters kept: a long one is cut, saying so
  for (size_t k = lines.size() > n ? lines.size() - n : 0; k < lines.size(); ++k)
    out += (out.empty() ? "" : " | ") +
           (lines[k].size() > kWidth ? lines[k].substr(0, kWidth) + "..." : lines[k]);
  return out;
}

struct Finished {
  int status = 0;  // waitpid's
  bool timed_out = false;
  double seconds = 0.0;  // from start to exit
};

// Runs `argv` in `folder` with stdin from /dev/null and stdout, stderr into files there, in a
// process group of its own (killed whole when it overruns `timeout_s`, and after it exits, so
// that nothing it started lives on).
Finished run_command(const std::vector<std::string>& argv, const fs::path& folder,
                     double timeout_s) {
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  std::vector<std::string> env_text;
  for (char** e = environ; *e; ++e)
    if (std::strncmp(*e, "FLATMARCH=", 10) != 0) env_text.push_back(*e);
  env_text.push_back("FLATMARCH=" + self_path());
  std::vector<char*> env;
  for (std::string& e : env_text) env.push_back(e.data());
  env.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  const std::string out = (folder / "stdout.txt").string(), err = (folder / "stderr.txt").string();
  posix_spawn_file_actions_addopen(&actions, 1, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&actions, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addchdir_np(&actions, folder.c_str());
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  sigset_t none, all;
  sigemptyset(&none);
  sigfillset(&all);
  posix_spawnattr_setsigmask(&attr, &none);
  posix_spawnattr_setsigdefault(&attr, &all);
  posix_spawnattr_setpgroup(&attr, 0);
  posix_spawnattr_setflags(&attr,
                           POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
  pid_t pid = 0;
  const auto started = std::chrono::steady_clock::now();
  const int spawned = posix_spawn(&pid, args[0], &actions, &attr, args.data(), env.data());
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  if (spawned != 0)
    throw std::runtime_error("cannot start " + argv[0] + ": " + std::strerror(spawned));
  Finished f;
  const auto deadline = started + std::chrono::duration<double>(timeout_s);
  // Polled: the wait is bounded by the deadline, and a frame takes far longer than a poll.
  for (auto pause = std::chrono::milliseconds(1);;
       pause = std::min(pause * 2, std::chrono::milliseconds(20))) {
    const pid_t done = waitpid(pid, &f.status, WNOHANG);
    if (done == pid) break;
    if (done < 0 && errno != EINTR) throw std::runtime_error("cannot wait for " + argv[0]);
    if (std::chrono::steady_clock::now() > deadline) {
      kill(-pid, SIGKILL);
      while (waitpid(pid, &f.status, 0) < 0 && errno == EINTR) {
      }
      f.timed_out = true;
      break;
    }
    std::this_thread::sleep_for(pause);
  }
  f.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  kill(-pid, SIGKILL);  // what it left running
  return f;
}

// A fresh folder for one frame, removed as it goes (kept where FLATMARCH_KEEP_EXTERNAL is set,
// to look into).
struct FrameFolder {
  fs::path path;
  FrameFolder() {
    std::string pattern = (fs::temp_directory_path() / "flatmarch-external-XXXXXX").string();
    if (!mkdtemp(pattern.data()))
      throw std::runtime_error("cannot make a folder in " + fs::temp_directory_path().string());
    path = pattern;
  }
  ~FrameFolder() {
    if (std::getenv("FLATMARCH_KEEP_EXTERNAL")) return;
    std::error_code ignored;
    fs::remove_all(path, ignored);
  }
  FrameFolder(const FrameFolder&) = delete;
  FrameFolder& operator=(const FrameFolder&) = delete;
};

double srgb_to_linear(double v) {
  return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}

class ExternalBackend final : public Backend {
 public:
  explicit ExternalBackend(ExternalManifest m) : m_(std::move(m)) {}
  std::string name() const override { return m_.name; }
  std::string description() const override {
    return "external renderer " + m_.name + (m_.info.version.empty() ? "" : " " + m_.info.version) +
           (m_.info.description.empty() ? "" : ": " + m_.info.description) + " (" +
           m_.info.manifest + ")";
  }
  Availability availability() const override {
    return m_.unavailable.empty() ? Availability{} : Availability{false, m_.unavailable};
  }
  std::vector<Method> methods() const override { return m_.methods; }
  std::vector<Precision> precisions() const override { return m_.precisions; }
  const ExternalInfo* external() const override { return &m_.info; }

  Frame render(const Scene& scene, const Camera& camera, int width, int height,
               const MarchParams& params, const Progress&) const override {
    if (const std::string why = m_.info.cannot_read(scene); !why.empty()) throw CaseSkipped(why);
    const FrameFolder folder;
    const json request =
        external_request(scene, camera, width, height, params, m_.info, folder.path);
    std::vector<std::string> argv = m_.command;
    argv.push_back(request.dump());
    const Finished f = run_command(argv, folder.path, m_.timeout_s);
    seconds_ = f.seconds;
    const std::string err = read_text(folder.path / "stderr.txt");
    const std::string who = m_.name;
    if (f.timed_out)
      throw std::runtime_error(who + " timed out: no answer in " +
                               std::to_string(static_cast<int>(m_.timeout_s)) +
                               " s (its manifest's timeout_s); killed");
    if (WIFSIGNALED(f.status))
      throw std::runtime_error(who + " was killed by signal " + std::to_string(WTERMSIG(f.status)) +
                               " (" + strsignal(WTERMSIG(f.status)) + ")" +
                               (err.empty() ? "" : ": " + last_lines(err, 4)));
    const int code = WEXITSTATUS(f.status);
    if (code == 77) {
      std::string why = err.substr(0, err.find('\n'));
      throw CaseSkipped(who + " cannot render it: " + (why.empty() ? "(it said nothing)" : why));
    }
    if (code != 0)
      throw std::runtime_error(who + " exited with status " + std::to_string(code) +
                               (err.empty() ? "" : ": " + last_lines(err, 4)));
    return read_frame(scene, width, height, request);
  }

  Trace trace(const Scene&, const Ray&, const MarchParams&, int) const override {
    throw std::runtime_error(m_.name + " is an external renderer: it traces no rays");
  }
  std::optional<double> last_frame_seconds() const override { return seconds_; }

 private:
  // The frame the renderer wrote, every channel its manifest lists checked.
  Frame read_frame(const Scene& scene, int width, int height, const json& request) const {
    const fs::path exr = request["output"]["exr"].get<std::string>();
    const fs::path png = request["output"]["png"].get<std::string>();
    const bool has_exr = fs::exists(exr), has_png = fs::exists(png);
    const ExternalInfo& info = m_.info;
    if (!has_exr && !has_png)
      throw std::runtime_error(m_.name + " wrote nothing: neither " + exr.filename().string() +
                               " nor " + png.filename().string() + " (it exited 0)");
    Frame frame(width, height);
    unsigned present = 0;
    if (has_exr) {
      Frame got;
      try {
        got = read_exr_channels(exr, present);
      } catch (const std::exception& e) {
        throw std::runtime_error(m_.name + "'s EXR cannot be read: " + e.what());
      }
      if (got.width != width || got.height != height)
        throw std::runtime_error(m_.name + "'s EXR is " + std::to_string(got.width) + "x" +
                                 std::to_string(got.height) + ", not the " + std::to_string(width) +
                                 "x" + std::to_string(height) + " asked");
      frame = std::move(got);
    } else {
      const float nan = std::numeric_limits<float>::quiet_NaN();
      std::fill(frame.rgb.begin(), frame.rgb.end(), nan);
      for (Channel* c : {&frame.steps, &frame.crossings, &frame.hit, &frame.t})
        std::fill(c->begin(), c->end(), nan);
    }
    const char* names[] = {"R", "G", "B", "steps", "crossings", "hit", "t"};
    const auto need = [&](int k, const char* channel) {
      if (!(present & (1u << k)))
        throw std::runtime_error(m_.name + " lists " + channel + " in its manifest, but " +
                                 (has_exr ? exr.filename().string() + " has no channel " + names[k]
                                          : "it wrote no EXR"));
    };
    if (info.colour && has_png) {
      Png image;
      try {
        image = read_png(png);
      } catch (const std::exception& e) {
        throw std::runtime_error(m_.name + "'s PNG cannot be read: " + e.what());
      }
      if (image.width != width || image.height != height)
        throw std::runtime_error(m_.name + "'s PNG is " + std::to_string(image.width) + "x" +
                                 std::to_string(image.height) + ", not the " +
                                 std::to_string(width) + "x" + std::to_string(height) + " asked");
      for (size_t k = 0; k < frame.rgb.size(); ++k)
        frame.rgb[k] = static_cast<float>(srgb_to_linear(image.rgb[k] / 255.0));
    } else if (info.colour) {
      for (int k = 0; k < 3; ++k) need(k, "colour");
    }
    if (info.steps) need(3, "steps");
    if (info.crossings) need(4, "crossings");
    if (info.hit) need(5, "hit");
    if (info.t) need(6, "t");
    check_values(scene, frame);
    return frame;
  }

  // Every value of the channels it gives is one that channel can hold.
  void check_values(const Scene& scene, const Frame& f) const {
    const ExternalInfo& info = m_.info;
    const int objects = static_cast<int>(scene.objects.size());
    for (int j = 0; j < f.height; ++j)
      for (int i = 0; i < f.width; ++i) {
        const size_t p = f.pixel(i, j);
        const auto bad = [&](const std::string& what, double v) {
          std::ostringstream s;
          s << m_.name << "'s " << what << " at pixel (" << i << ", " << j << ") is " << v;
          return std::runtime_error(s.str());
        };
        const double hit = f.hit[p], crossings = f.crossings[p], steps = f.steps[p];
        if (info.hit &&
            (!std::isfinite(hit) || hit != std::round(hit) || hit < kHitVertex || hit >= objects))
          throw bad("hit", hit);
        if (info.crossings &&
            (!std::isfinite(crossings) || crossings < 0.0 || crossings != std::round(crossings)))
          throw bad("crossings count", crossings);
        if (info.steps && (!std::isfinite(steps) || steps < 0.0)) throw bad("steps", steps);
        if (info.t && std::isnan(f.t[p])) throw bad("t", f.t[p]);
        if (info.colour)
          for (int k = 0; k < 3; ++k)
            if (!std::isfinite(f.rgb[3 * p + static_cast<size_t>(k)]))
              throw bad("colour", f.rgb[3 * p + static_cast<size_t>(k)]);
      }
  }

  ExternalManifest m_;
  mutable std::optional<double> seconds_;
};

// The channels a renderer gives, by their names in the protocol.
json channel_list(const ExternalInfo& info) {
  json channels = json::array();
  for (const auto& [has, channel] :
       std::vector<std::pair<bool, const char*>>{{info.colour, "colour"},
                                                 {info.hit, "hit"},
                                                 {info.crossings, "crossings"},
                                                 {info.steps, "steps"},
                                                 {info.t, "t"}})
    if (has) channels.push_back(channel);
  return channels;
}

[[noreturn]] void refuse(const fs::path& file, const std::string& pointer, const std::string& why) {
  throw std::invalid_argument(file.string() + ": " + pointer + ": " + why);
}

std::vector<std::string> string_list(const json& doc, const fs::path& file, const char* key,
                                     const std::vector<std::string>& allowed) {
  const json& v = doc.at(key);
  if (!v.is_array() || v.empty())
    refuse(file, std::string("/") + key, "a list of at least one of: " + joined(allowed));
  std::vector<std::string> list;
  for (size_t k = 0; k < v.size(); ++k) {
    const std::string pointer = std::string("/") + key + "/" + std::to_string(k);
    if (!v[k].is_string()) refuse(file, pointer, "a string, one of: " + joined(allowed));
    const std::string s = v[k].get<std::string>();
    if (!allowed.empty() && !among(allowed, s))
      refuse(file, pointer, "\"" + s + "\" is none of: " + joined(allowed));
    list.push_back(s);
  }
  return list;
}

}  // namespace

ExternalManifest read_manifest(const fs::path& file, const std::string& name) {
  json doc;
  try {
    doc = read_json_file(file);
  } catch (const std::exception& e) {
    throw std::invalid_argument(e.what());
  }
  if (!doc.is_object()) refuse(file, "/", "a manifest is a JSON object (docs/external.md)");
  const std::set<std::string> keys = {"protocol",   "name",          "version",     "description",
                                      "command",    "channels",      "look",        "methods",
                                      "parameters", "fixed",         "precisions",  "scene_formats",
                                      "timeout_s",  "frame_seconds", "expectations"};
  for (const auto& [key, value] : doc.items())
    if (!keys.count(key))
      refuse(file, "/" + key, "no such key in " + std::string(kExternalProtocol));
  if (!doc.contains("protocol") || doc["protocol"] != kExternalProtocol)
    refuse(
        file, "/protocol",
        std::string("must be \"") + kExternalProtocol + "\", the protocol this flatmarch speaks");
  ExternalManifest m;
  const fs::path folder = fs::absolute(file).parent_path();
  m.info.manifest = fs::absolute(file).lexically_normal().string();
  const auto text = [&](const char* key) -> std::string {
    if (!doc.contains(key)) return {};
    if (!doc[key].is_string()) refuse(file, std::string("/") + key, "a string");
    return doc[key].get<std::string>();
  };
  m.name = name.empty() ? text("name") : name;
  if (m.name.empty()) refuse(file, "/name", "a renderer needs a name (or --external NAME=...)");
  if (m.name.find_first_not_of(
          "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-") != std::string::npos)
    refuse(file, "/name", "\"" + m.name + "\": letters, digits, _ and - only");
  m.info.version = text("version");
  m.info.description = text("description");

  if (!doc.contains("command")) refuse(file, "/command", "missing: the program to call");
  m.command = string_list(doc, file, "command", {});
  for (size_t k = 0; k < m.command.size(); ++k) {
    std::string& a = m.command[k];
    if (a.empty()) refuse(file, "/command/" + std::to_string(k), "an empty argument");
    // An argument naming a file beside the manifest is taken from there.
    if (fs::path(a).is_relative() && a[0] != '-' && fs::exists(folder / a))
      a = (folder / a).lexically_normal().string();
    else if (k == 0 && a.find('/') == std::string::npos) {
      const std::string found = on_path(a);
      if (found.empty())
        m.unavailable = "its command " + a + " is not on PATH";
      else
        a = found;
    } else if (k == 0 && access(a.c_str(), X_OK) != 0) {
      m.unavailable = "its command " + a + " is not there or cannot run";
    }
  }

  if (!doc.contains("channels"))
    refuse(file, "/channels", "missing: what it writes, of " + joined(kChannels));
  const std::vector<std::string> channels = string_list(doc, file, "channels", kChannels);
  m.info.colour = among(channels, "colour");
  m.info.hit = among(channels, "hit");
  m.info.crossings = among(channels, "crossings");
  m.info.steps = among(channels, "steps");
  m.info.t = among(channels, "t");
  if ((m.info.crossings || m.info.t) && !m.info.hit)
    refuse(file, "/channels", "crossings and t are judged on the rays whose hit is known: add hit");
  m.info.look = doc.contains("look") ? text("look") : "flatmarch";
  if (!among(kLooks, m.info.look))
    refuse(file, "/look", "\"" + m.info.look + "\" is none of: " + joined(kLooks));
  if (m.info.colour && m.info.look == "none") m.info.colour = false;

  const std::vector<std::string> methods =
      doc.contains("methods") ? string_list(doc, file, "methods", {"sphere", "relaxed", "analytic"})
                              : std::vector<std::string>{"sphere", "relaxed", "analytic"};
  for (const std::string& s : methods) m.methods.push_back(*parse_method(s));
  if (doc.contains("parameters") && !(doc["parameters"].is_array() && doc["parameters"].empty()))
    m.parameters = string_list(doc, file, "parameters", kParameters);
  if (doc.contains("fixed")) {
    if (!doc["fixed"].is_object()) refuse(file, "/fixed", "an object of parameter: value");
    for (const auto& [key, value] : doc["fixed"].items()) {
      if (!among(kParameters, key))
        refuse(file, "/fixed/" + key, "no such parameter (" + joined(kParameters) + ")");
      if (!value.is_number() || !(value.get<double>() > 0.0))
        refuse(file, "/fixed/" + key, "a positive number");
      m.info.fixed.emplace_back(key, value.get<double>());
    }
  }
  const std::vector<std::string> precisions =
      doc.contains("precisions") ? string_list(doc, file, "precisions", {"f32", "f64"})
                                 : std::vector<std::string>{"f32"};
  for (const std::string& p : precisions)
    m.precisions.push_back(p == "f64" ? Precision::f64 : Precision::f32);
  if (doc.contains("scene_formats"))
    m.info.scene_formats = string_list(doc, file, "scene_formats", kFormats);
  const auto positive = [&](const char* key, double fallback) {
    if (!doc.contains(key)) return fallback;
    if (!doc[key].is_number() || !(doc[key].get<double>() > 0.0))
      refuse(file, std::string("/") + key, "a positive number of seconds");
    return doc[key].get<double>();
  };
  m.timeout_s = positive("timeout_s", 120.0);
  m.frame_seconds = positive("frame_seconds", 1.0);
  if (doc.contains("expectations")) {
    const fs::path e = folder / text("expectations");
    if (!fs::exists(e)) refuse(file, "/expectations", "no file " + e.string());
    m.info.expectations = e.lexically_normal().string();
  }
  return m;
}

json external_json(const ExternalInfo& info) {
  const json channels = channel_list(info);
  json fixed = json::object();
  for (const auto& [name, value] : info.fixed) fixed[name] = value;
  return {{"manifest", info.manifest},
          {"version", info.version},
          {"description", info.description},
          {"look", info.look},
          {"channels", channels},
          {"fixed", fixed},
          {"time", "the command's, from its start to its exit"}};
}

std::unique_ptr<Backend> make_external(const ExternalManifest& manifest) {
  return std::make_unique<ExternalBackend>(manifest);
}

BackendEntry external_entry(const std::string& spec) {
  const size_t eq = spec.find('=');
  const std::string name = eq == std::string::npos ? std::string() : spec.substr(0, eq);
  const std::string file = eq == std::string::npos ? spec : spec.substr(eq + 1);
  if (file.empty()) throw std::invalid_argument("--external " + spec + ": NAME=MANIFEST");
  if (!fs::exists(file)) throw std::invalid_argument("--external " + spec + ": no file " + file);
  const ExternalManifest m = read_manifest(file, name);
  BackendEntry entry;
  entry.name = m.name;
  entry.kernel = true;
  entry.make = [m](const BackendOptions&) { return make_external(m); };
  entry.cost.frame_seconds = m.frame_seconds;
  entry.test_batch = "external";
  return entry;
}

json external_request(const Scene& scene, const Camera& camera, int width, int height,
                      const MarchParams& params, const ExternalInfo& info, const fs::path& folder) {
  json scene_doc;
  if (!scene.imported_from.empty() && scene.source_file.empty())
    scene_doc = import_peer_file(scene.imported_from).scene;
  else if (!scene.source_file.empty())
    scene_doc = read_json_file(scene.source_file);
  else
    throw std::runtime_error("scene " + scene.name +
                             " was made in code: there is no file to give an external renderer");
  scene_doc["name"] = scene.name;
  const fs::path scene_file = folder / "scene.json";
  std::ofstream(scene_file) << scene_doc.dump(2) << "\n";
  const json channels = channel_list(info);
  json request = {
      {"protocol", kExternalProtocol},
      {"scene", scene_doc},
      {"scene_file", scene_file.string()},
      {"camera",
       {{"polygon", camera.polygon},
        {"position", {camera.position.x, camera.position.y, camera.position.z}},
        {"yaw_deg", camera.yaw_deg},
        {"pitch_deg", camera.pitch_deg},
        {"fov_deg", camera.fov_deg}}},
      {"width", width},
      {"height", height},
      {"method", to_string(params.method)},
      {"params",
       {{"eps", params.eps},
        {"offset", params.offset},
        {"max_steps", params.max_steps},
        {"max_distance", params.max_distance},
        {"omega", params.omega},
        {"precision", params.precision == Precision::f64 ? "f64" : "f32"}}},
      {"channels", channels},
      {"output",
       {{"exr", (folder / "frame.exr").string()}, {"png", (folder / "frame.png").string()}}}};
  if (!scene.imported_from.empty())
    request["imported_from"] = {{"format", "peer-app"}, {"file", scene.imported_from}};
  return request;
}

std::optional<Channel> look_colours(const std::string& look, const Scene& scene,
                                    const Camera& camera, int width, int height,
                                    const MarchParams& params) {
  if (look != "peer-app") return std::nullopt;
  // The app's colours (its template.frag): a decoration's normal, in its frame (y up: our
  // (x, z, y)), as 0.5 + 0.5 n; a wall 0.9 grey; anything else its white sky; less
  // fog_effect_strength (the scene's wall_tint, as import-peer converts it) for each crossing;
  // written to the canvas as they are, display values, which the frame holds as linear colour.
  Channel rgb(3 * static_cast<size_t>(width) * static_cast<size_t>(height));
  const CameraBasis<double> basis =
      camera_basis(camera.yaw_deg, camera.pitch_deg, camera.fov_deg, width, height);
  const double darkening = scene.look.wall_tint;
  for (int j = 0; j < height; ++j)
    for (int i = 0; i < width; ++i) {
      const Ray ray{camera.polygon, camera.position, camera_ray(basis, i, j, width, height)};
      const RayEnd end = oracle_trace(scene, ray, params).end;
      Vec3 c(1.0);
      if (end.hit >= 0)
        c = 0.5 + 0.5 * Vec3(end.normal.x, end.normal.z, end.normal.y);
      else if (end.hit == kHitWall)
        c = Vec3(0.9);
      c -= darkening * end.crossings;
      const size_t p =
          3 * (static_cast<size_t>(j) * static_cast<size_t>(width) + static_cast<size_t>(i));
      for (int k = 0; k < 3; ++k)
        rgb[p + static_cast<size_t>(k)] =
            static_cast<float>(srgb_to_linear(std::clamp(c[k], 0.0, 1.0)));
    }
  return rgb;
}

ExternalSkips::ExternalSkips(const std::vector<std::unique_ptr<Backend>>& backends) {
  for (const auto& backend : backends)
    if (const ExternalInfo* info = backend->external(); info && !info->expectations.empty()) {
      try {
        files_[backend->name()] = Expectations::read(info->expectations);
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument("--external " + backend->name() + ": " + e.what());
      }
    }
}

std::string ExternalSkips::why(const Backend& backend, Method m, const Scene& scene) const {
  const ExternalInfo* info = backend.external();
  if (!info) return {};
  const std::vector<Method> methods = backend.methods();
  if (std::find(methods.begin(), methods.end(), m) == methods.end())
    return "it renders no " + std::string(to_string(m)) + " cases (its manifest's methods)";
  if (std::string why = info->cannot_read(scene); !why.empty()) return why;
  const auto file = files_.find(backend.name());
  if (file != files_.end() &&
      file->second.skipped(case_key(backend.name(), to_string(m), scene.name)))
    return "its expectation file skips it (" + file->second.file() + ")";
  return {};
}

}  // namespace flatmarch::conformance
