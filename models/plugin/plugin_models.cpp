#include "models/plugin/plugin_models.h"

#include "core/error.h"
#include "core/parallel.h"
#include "models/registry.h"

#include <hairbench/plugin.h>

#include <dlfcn.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <deque>
#include <memory>
#include <regex>
#include <sstream>

namespace hairbench::plugin {

namespace {

constexpr std::size_t kErrorSize = 512;

// The stage an ABI stage is reported as (hb_stage, in the report's timing.stages).
Stage stage_of(int s) {
  switch (s) {
    case HB_STAGE_INTEGRATE: return Stage::Integrate;
    case HB_STAGE_LENGTH: return Stage::Length;
    case HB_STAGE_COLLISION: return Stage::Collision;
    default: return Stage::LocalShape;
  }
}

void copy_matrix(const Affine3f& a, float (&out)[16]) {
  const Eigen::Matrix4f m = a.matrix();
  std::copy(m.data(), m.data() + 16, out);
}

void copy_vec(const Vec3f& v, float (&out)[3]) {
  out[0] = v.x();
  out[1] = v.y();
  out[2] = v.z();
}

// One plugin model behind the HairModel interface. Once the plugin fails, the model
// stops calling it: its positions stay the last good ones and failure() says why.
class PluginModel final : public HairModel {
 public:
  PluginModel(const hb_model_desc& desc, std::string library, const ModelContext& ctx)
      : desc_(desc), library_(std::move(library)), pool_(ctx.pool) {
    host_ = {this, &PluginModel::parallel_for, &PluginModel::stage_time, pool_ ? pool_->threads() : 1,
             ctx.skip_inert ? 1 : 0};
    char err[kErrorSize] = {};
    guarded("create", err, [&] {
      model_ = desc_.create(&host_, err, sizeof err);
      return model_ != nullptr;
    });
  }
  ~PluginModel() override {
    if (model_) guarded_destroy();
  }
  PluginModel(const PluginModel&) = delete;
  PluginModel& operator=(const PluginModel&) = delete;

  void reset(const Groom& rest, const ParamSet& params) override {
    rest_vertices_ = rest.vertex_count();
    own_.assign(rest.positions.begin(), rest.positions.end());
    view_ = own_;
    rest_xyzw_.resize(4 * rest.vertex_count());
    for (std::size_t v = 0; v < rest.vertex_count(); ++v)
      std::copy(rest.positions[v].data(), rest.positions[v].data() + 4, &rest_xyzw_[4 * v]);
    offsets_ = rest.strand_offsets;
    strand_region_ = rest.strand_region;
    groom_ = {rest.strand_count(), offsets_.data(), rest.vertex_count(), rest_xyzw_.data(),
              strand_region_.data(), rest.region_names.size(), rest.head_radius};
    base_.clear();
    region_values_.clear();
    for (std::size_t i = 0; i < desc_.param_count; ++i) base_.push_back(params.get(desc_.params[i].name));
    for (std::size_t r = 0; r < rest.region_names.size(); ++r)
      for (std::size_t i = 0; i < desc_.param_count; ++i) region_values_.push_back(params.get(desc_.params[i].name, r));
    call_reset(nullptr);
  }

  // The ABI takes an initial state at reset (hb_initial_state): the plugin is reset again
  // with the rest groom it was given (kept here) and these positions.
  bool start_from(std::span<const Vec4f> positions) override {
    if (positions.size() != rest_vertices_) start_positions(positions, own_);  // throws: the wrong layout
    std::vector<float> xyzw(4 * positions.size());
    for (std::size_t v = 0; v < positions.size(); ++v) {
      std::copy(positions[v].data(), positions[v].data() + 3, &xyzw[4 * v]);
      xyzw[4 * v + 3] = rest_xyzw_[4 * v + 3];
    }
    const hb_initial_state initial{xyzw.data(), nullptr};
    call_reset(&initial);
    // A plugin that ignores the initial state starts at rest, and a truth run would read
    // its stillness as a result: it says it cannot be kicked instead.
    if (!failure_.empty() || view_.size() != positions.size()) return false;
    for (std::size_t v = 0; v < positions.size(); ++v)
      if ((view_[v].head<3>() - positions[v].head<3>()).norm() > 1e-6f * (1.0f + positions[v].head<3>().norm()))
        return false;
    return true;
  }

  void step(const FrameInput& in, StageTimes& out_times) override {
    if (!failure_.empty() || !model_) return;
    hb_frame f{};
    f.frame = in.frame;
    f.t = in.t;
    f.dt = in.dt;
    copy_matrix(in.head_prev, f.head_prev);
    copy_matrix(in.head, f.head);
    copy_vec(in.gravity, f.gravity);
    copy_vec(in.gravity_at_rest(), f.rest_gravity);
    copy_vec(in.wind.active() ? in.wind.acceleration() : Vec3f(Vec3f::Zero()), f.wind);
    spheres_.resize(4 * in.colliders.size());
    write_spheres(in.colliders, in.head, spheres_.data());
    f.spheres = spheres_.data();
    f.sphere_count = in.colliders.size();
    times_ = &out_times;
    char err[kErrorSize] = {};
    if (guarded("step", err, [&] { return desc_.step(model_, &f, err, sizeof err) == HB_OK; })) fetch_positions();
    times_ = nullptr;
  }

  std::span<const Vec4f> positions() const override { return view_; }
  std::string failure() const override { return failure_; }

 private:
  void call_reset(const hb_initial_state* initial) {
    if (!model_ || !failure_.empty()) return;
    const hb_params p{desc_.param_count, base_.data(), groom_.region_count, region_values_.data()};
    char err[kErrorSize] = {};
    if (guarded("reset", err, [&] { return desc_.reset(model_, &groom_, &p, initial, err, sizeof err) == HB_OK; }))
      fetch_positions();
  }

  // Calls into the plugin; false (and the model failed) when it returned an error or threw.
  template <class Call>
  bool guarded(const char* what, const char* err, Call&& call) {
    try {
      if (call() && thread_failure_.empty()) return true;
      fail(what, thread_failure_.empty() ? (err[0] ? std::string(err) : std::string("returned an error")) : thread_failure_);
    } catch (const std::exception& e) {
      fail(what, std::string("threw across the ABI boundary: ") + e.what());
    } catch (...) {
      fail(what, "threw across the ABI boundary (not a std::exception)");
    }
    return false;
  }
  void guarded_destroy() noexcept {
    try {
      desc_.destroy(model_);
    } catch (...) {
      // A destructor cannot report; the model is gone either way.
    }
  }
  void fail(const char* what, const std::string& why) {
    if (failure_.empty()) failure_ = std::string(desc_.name) + " (plugin " + library_ + ") " + what + ": " + why;
  }

  // Takes the plugin's positions after a call: in place when they are aligned as Vec4f
  // needs (no copy inside the timed step), else copied. A wrong count fails the model.
  void fetch_positions() {
    std::size_t count = 0;
    const float* p = nullptr;
    char err[kErrorSize] = {};
    if (!guarded("positions", err, [&] {
          p = desc_.positions(model_, &count);
          return true;
        }))
      return;
    if (!p || count != rest_vertices_) {
      std::ostringstream why;
      why << "returned " << (p ? std::to_string(count) : std::string("no")) << " positions for a groom of "
          << rest_vertices_ << " vertices";
      fail("positions", why.str());
      return;
    }
    if (reinterpret_cast<std::uintptr_t>(p) % alignof(Vec4f) == 0) {
      view_ = {reinterpret_cast<const Vec4f*>(p), count};
    } else {
      for (std::size_t v = 0; v < count; ++v) own_[v] = Vec4f(p[4 * v], p[4 * v + 1], p[4 * v + 2], p[4 * v + 3]);
      view_ = own_;
    }
  }

  // hb_host::parallel_for: the harness's pool; an exception thrown by the plugin's body on
  // a worker is caught there and fails the model after the loop.
  static void parallel_for(void* ctx, std::size_t count, void (*fn)(void*, std::size_t, std::size_t), void* user) {
    auto* self = static_cast<PluginModel*>(ctx);
    std::atomic<bool> threw{false};
    auto body = [&](std::size_t b, std::size_t e) {
      try {
        fn(user, b, e);
      } catch (...) {
        threw = true;
      }
    };
    if (self->pool_) self->pool_->parallel_for(count, body);
    else body(0, count);
    if (threw && self->thread_failure_.empty())
      self->thread_failure_ = "threw across the ABI boundary in a parallel_for body";
  }
  static void stage_time(void* ctx, int stage, double ms) {
    auto* self = static_cast<PluginModel*>(ctx);
    if (self->times_ && std::isfinite(ms) && ms >= 0.0) self->times_->add(stage_of(stage), ms);
  }

  const hb_model_desc& desc_;
  const std::string library_;
  ThreadPool* pool_;
  hb_host host_{};
  void* model_ = nullptr;
  std::size_t rest_vertices_ = 0;
  // The groom as the plugin was given it, kept for call_reset.
  std::vector<float> rest_xyzw_;
  std::vector<std::uint32_t> offsets_;
  std::vector<std::uint16_t> strand_region_;
  hb_groom groom_{};
  std::vector<double> base_, region_values_;
  std::vector<Vec4f> own_;
  std::span<const Vec4f> view_;
  std::vector<float> spheres_;
  StageTimes* times_ = nullptr;
  std::string failure_;
  std::string thread_failure_;
};

// What the registry keeps of a plugin: the handle (never closed: the models' names and
// functions live in it) and the converted parameter specs.
struct Record {
  Library library;
  void* handle = nullptr;
  std::deque<std::vector<ParamSpec>> params;
};

std::deque<Record>& records() {
  static std::deque<Record> r;
  return r;
}

std::vector<Library>& libraries() {
  static std::vector<Library> l;
  return l;
}

bool valid_name(const char* s) { return s && std::regex_match(s, std::regex("[a-z0-9_]+")); }

ParamRole role_of(int r) {
  switch (r) {
    case HB_ROLE_STIFFNESS: return ParamRole::stiffness;
    case HB_ROLE_DAMPING: return ParamRole::damping;
    case HB_ROLE_COST_KNOB: return ParamRole::cost_knob;
    case HB_ROLE_CHAIN_LIMIT: return ParamRole::chain_limit;
    default: return ParamRole::none;
  }
}

// The parameter specs of one model, checked: valid names, finite ranges, defaults inside.
std::vector<ParamSpec> convert_params(const hb_model_desc& d, const std::string& where) {
  if (d.param_count > 0 && !d.params) throw InputError(where, "params", "param_count > 0 but no array");
  std::vector<ParamSpec> out;
  for (std::size_t i = 0; i < d.param_count; ++i) {
    const hb_param_spec& p = d.params[i];
    const std::string at = "params[" + std::to_string(i) + "]";
    if (!valid_name(p.name)) throw InputError(where, at + ".name", "missing or not [a-z0-9_]+");
    for (const ParamSpec& q : out)
      if (q.name == p.name) throw InputError(where, at + ".name", std::string("'") + p.name + "' given twice");
    if (!std::isfinite(p.min) || !std::isfinite(p.max) || !std::isfinite(p.default_value) || p.min > p.max ||
        p.default_value < p.min || p.default_value > p.max ||
        (p.integer && p.default_value != std::floor(p.default_value)))
      throw InputError(where, at, std::string("'") + p.name + "': the default must be finite and in [min, max]" +
                                      (p.integer ? ", and whole" : ""));
    out.push_back({p.name, p.default_value, p.min, p.max, p.integer != 0, p.help ? p.help : "", role_of(p.role),
                   p.chain_value});
  }
  return out;
}

// The settings at which a plugin model is its own converged solution: every cost knob 8
// times its default, within its range.
std::vector<ParamValue> converged_of(const std::vector<ParamSpec>& params) {
  std::vector<ParamValue> out;
  for (const ParamSpec& p : params)
    if (p.role == ParamRole::cost_knob) out.push_back({p.name, std::min(p.max, 8.0 * std::max(p.default_value, 1.0))});
  return out;
}

ModelInfo model_info(const hb_model_desc& d, Record& rec, const std::string& where) {
  if (!valid_name(d.name)) throw InputError(where, "name", "missing or not [a-z0-9_]+");
  if (!d.create || !d.reset || !d.step || !d.positions || !d.destroy)
    throw InputError(where, "functions", std::string(d.name) + ": create, reset, step, positions and destroy are all required");
  if (!std::isfinite(d.cost_ns_per_vertex) || d.cost_ns_per_vertex < 0.0)
    throw InputError(where, "cost_ns_per_vertex", std::string(d.name) + ": must be finite and >= 0");
  const std::vector<ParamSpec>& params = rec.params.emplace_back(convert_params(d, where));
  if (d.cost_multiplier && std::none_of(params.begin(), params.end(), [&](const ParamSpec& p) { return p.name == d.cost_multiplier; }))
    throw InputError(where, "cost_multiplier", std::string("'") + d.cost_multiplier + "' is not a parameter of " + d.name);
  ModelInfo m;
  m.name = d.name;
  m.summary = d.summary ? d.summary : "";
  m.params = params;
  const std::string library = rec.library.path;
  m.make = [&d, library](const ModelContext& c) -> std::unique_ptr<HairModel> {
    return std::make_unique<PluginModel>(d, library, c);
  };
  m.cost = {d.cost_ns_per_vertex, true, d.cost_multiplier ? std::string_view(d.cost_multiplier) : std::string_view()};
  m.converged = converged_of(params);
  m.origin = rec.library.path;
  return m;
}

// The library's description, checked before anything but its version is read.
const hb_plugin& describe(void* handle, const std::string& where) {
  void* entry = dlsym(handle, HAIRBENCH_PLUGIN_ENTRY);
  if (!entry) throw InputError(where, HAIRBENCH_PLUGIN_ENTRY, "no such entry point (is it exported extern \"C\"?)");
  const hb_plugin* p = nullptr;
  try {
    p = reinterpret_cast<hb_plugin_entry>(entry)();
  } catch (...) {
    throw InputError(where, HAIRBENCH_PLUGIN_ENTRY, "threw across the ABI boundary");
  }
  if (!p) throw InputError(where, HAIRBENCH_PLUGIN_ENTRY, "returned no description");
  if (p->abi_version != HAIRBENCH_PLUGIN_ABI_VERSION)
    throw InputError(where, "abi_version",
                     "built for plugin ABI " + std::to_string(p->abi_version) + "; this hairbench speaks ABI " +
                         std::to_string(HAIRBENCH_PLUGIN_ABI_VERSION) + " (rebuild it against this hairbench's plugin.h)");
  if (!p->models || p->model_count == 0) throw InputError(where, "models", "the plugin describes no model");
  return *p;
}

}  // namespace

const Library& load(const std::filesystem::path& path) {
  std::error_code ec;
  const std::filesystem::path canonical = std::filesystem::weakly_canonical(path, ec);
  const std::string where = (ec ? path : canonical).string();
  for (const Library& l : libraries())
    if (l.path == where) return l;
  if (!std::filesystem::is_regular_file(path)) throw InputError(where, "plugin", "no such file");
  void* handle = dlopen(where.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!handle) throw InputError(where, "plugin", std::string("cannot be loaded: ") + dlerror());
  Record rec;
  rec.handle = handle;
  rec.library.path = where;
  try {
    const hb_plugin& p = describe(handle, where);
    rec.library.name = p.name ? p.name : std::filesystem::path(where).stem().string();
    std::vector<ModelInfo> models;
    for (std::size_t i = 0; i < p.model_count; ++i) {
      models.push_back(model_info(p.models[i], rec, where));
      rec.library.models.emplace_back(p.models[i].name);
    }
    Record& kept = records().emplace_back(std::move(rec));
    // The converted specs moved with the record; point the models at the kept copies.
    for (std::size_t i = 0; i < models.size(); ++i) {
      models[i].params = kept.params[i];
      models[i].origin = kept.library.path;
    }
    add_models(std::move(models), where);
    libraries().push_back(kept.library);
  } catch (...) {
    if (!records().empty() && records().back().handle == handle) records().pop_back();
    dlclose(handle);
    throw;
  }
  return libraries().back();
}

const std::vector<Library>& loaded() { return libraries(); }

std::vector<std::string> load_defaults(const std::vector<std::string>& names,
                                       const std::vector<std::filesystem::path>& dirs) {
  std::vector<std::string> left_out;
  for (const std::string& name : names) {
    std::filesystem::path found;
    for (const std::filesystem::path& d : dirs)
      if (found.empty() && std::filesystem::is_regular_file(d / (name + ".so"))) found = d / (name + ".so");
    if (found.empty()) {
      std::string where;
      for (const std::filesystem::path& d : dirs) where += (where.empty() ? "" : ", ") + d.string();
      left_out.push_back(name + ": not loaded: no " + name + ".so in " + (where.empty() ? "(no plugin folder)" : where));
      continue;
    }
    try {
      load(found);
    } catch (const InputError& e) {
      left_out.push_back(name + ": not loaded: " + e.what());
    }
  }
  return left_out;
}

void load_search_path(const std::string& path_list) {
  std::stringstream in(path_list);
  std::string entry;
  while (std::getline(in, entry, ':')) {
    if (entry.empty()) continue;
    const std::filesystem::path p(entry);
    if (!std::filesystem::is_directory(p)) {
      load(p);
      continue;
    }
    std::vector<std::filesystem::path> files;
    for (const auto& f : std::filesystem::directory_iterator(p))
      if (f.is_regular_file() && f.path().extension() == ".so") files.push_back(f.path());
    std::sort(files.begin(), files.end());
    for (const std::filesystem::path& f : files) load(f);
  }
}

}  // namespace hairbench::plugin
