#include "harness/at_rest_cache.h"

#include <algorithm>
#include <chrono>
#include <cstring>

namespace hairbench {

namespace {

// A key for this process's cache over 64-bit words (then the bytes left over), several
// times faster than byte-wise Fnv64 on the megabytes of a TressFX groom, which every
// lane's probe and twin hash. Each word is xored in, multiplied by an odd constant (which
// carries its bits upwards) and the high half folded back down: without the fold, the
// same top bit flipped in two words (two floats' signs) would cancel.
class KeyHash {
 public:
  KeyHash& bytes(const void* p, std::size_t n) {
    const auto* c = static_cast<const unsigned char*>(p);
    std::size_t i = 0;
    for (; i + 8 <= n; i += 8) {
      std::uint64_t w;
      std::memcpy(&w, c + i, 8);
      mix(w);
    }
    for (; i < n; ++i) mix(c[i]);
    return *this;
  }
  template <class T>
  KeyHash& value(const T& v) {
    return bytes(&v, sizeof v);
  }
  KeyHash& text(const std::string& s) {
    value(s.size());
    return bytes(s.data(), s.size());
  }
  std::uint64_t digest() const { return h_; }

 private:
  void mix(std::uint64_t w) {
    h_ ^= w;
    h_ *= 0x9e3779b97f4a7c15ull;
    h_ ^= h_ >> 32;
  }
  std::uint64_t h_ = 0xcbf29ce484222325ull;
};

void hash_groom(KeyHash& h, const Groom& g) {
  h.value(g.positions.size()).bytes(g.positions.data(), g.positions.size() * sizeof(Vec4f));
  h.value(g.strand_offsets.size()).bytes(g.strand_offsets.data(), g.strand_offsets.size() * sizeof(std::uint32_t));
  h.value(g.strand_region.size()).bytes(g.strand_region.data(), g.strand_region.size() * sizeof(std::uint16_t));
  h.value(g.region_names.size());
  for (const std::string& r : g.region_names) h.text(r);
  h.value(g.head_radius);
}

template <class T>
void hash_vector(KeyHash& h, const std::vector<T>& v) {
  h.value(v.size()).bytes(v.data(), v.size() * sizeof(T));
}

void hash_vec3(KeyHash& h, const Vec3f& v) { h.value(v.x()).value(v.y()).value(v.z()); }

void hash_spheres(KeyHash& h, const std::vector<Sphere>& spheres) {
  h.value(spheres.size());
  for (const Sphere& c : spheres) {
    hash_vec3(h, c.center);
    h.value(c.radius).value(c.head_attached);
  }
}

// The model as made (make_model, probe_at_rest): which one, where it came from, on which
// device, with which parameters.
void hash_model(KeyHash& h, const ModelInfo& info, const ParamSet& params, const std::string& device) {
  h.text(std::string(info.name)).text(std::string(info.origin)).text(device);
  h.value(params.base().size());
  for (const auto& [name, v] : params.base()) h.text(name).value(v);
  h.value(params.regions().size());
  for (const auto& region : params.regions()) {
    h.value(region.size());
    for (const auto& [name, v] : region) h.text(name).value(v);
  }
}

// The full groom and, where follow hairs are rebuilt, the guides the models simulate and
// the layout they are rebuilt with (make_model).
void hash_strands(KeyHash& h, const Scenario& sc) {
  hash_groom(h, sc.groom);
  h.value(sc.follow.has_value());
  if (!sc.follow) return;
  hash_groom(h, sc.guides);
  const tfx::FollowHairs& f = *sc.follow;
  hash_vector(h, f.guide_offsets);
  hash_vector(h, f.guide);
  hash_vector(h, f.anchor);
  hash_vector(h, f.follow_offsets);
  hash_vector(h, f.offsets);
}

}  // namespace

AtRest AtRestCache::probe(const ModelInfo& info, const Scenario& sc, const ParamSet& params, ThreadPool& pool,
                          const std::string& device, AtRestParts parts, std::string& from) {
  // probe_at_rest reads the simulated strands, dt, gravity and the colliders at the rest pose.
  KeyHash h;
  hash_model(h, info, params, device);
  h.value(parts.probe).value(parts.mode);
  hash_strands(h, sc);
  h.value(sc.dt);
  hash_vec3(h, sc.gravity);
  hash_spheres(h, sc.colliders);
  const std::uint64_t key = h.digest();
  {
    const std::lock_guard lock(mutex_);
    const auto it = probes_.find(key);
    if (it != probes_.end()) {
      from = it->second.scenario;
      return it->second.at_rest;
    }
  }
  from.clear();
  AtRest out = probe_at_rest(info, sc, params, pool, device, parts);
  const std::lock_guard lock(mutex_);
  probes_.emplace(key, ProbeEntry{out, sc.name});
  return out;
}

RestTwin AtRestCache::twin(const ModelInfo& info, const Scenario& sc, const ParamSet& params, ThreadPool& pool,
                           const std::string& device, bool skip_inert, int frames, std::string& from) {
  // rest_twin reads the strands, dt, gravity turned into the final pose's frame, and the
  // colliders where that pose puts them, seen from the head (harness/twin.h); the pose
  // itself only through those.
  const Affine3f head = sc.head.at(frames * sc.dt);
  const Affine3f to_head = head.inverse();
  KeyHash h;
  hash_model(h, info, params, device);
  h.value(skip_inert);
  hash_strands(h, sc);
  h.value(sc.dt);
  hash_vec3(h, Vec3f(to_head.linear() * sc.gravity));
  hash_vec3(h, sc.gravity);
  h.value(sc.colliders.size());
  for (const Sphere& c : sc.colliders) {
    hash_vec3(h, Vec3f(to_head * collider_center(c, head)));
    h.value(c.radius);
  }
  const std::uint64_t key = h.digest();
  {
    const std::lock_guard lock(mutex_);
    for (const TwinEntry& e : twins_)
      if (e.key == key && (e.asked == frames || (e.twin.at_rest && e.twin.frames <= frames))) {
        from = e.scenario;
        RestTwin out = e.twin;
        out.head = head;
        return out;
      }
  }
  from.clear();
  const auto start = std::chrono::steady_clock::now();
  RestTwin out = rest_twin(info, sc, params, pool, device, skip_inert, frames);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  auto bytes = [](const TwinEntry& e) { return std::max<std::size_t>(1, e.twin.positions.size() * sizeof(Vec4f)); };
  const std::lock_guard lock(mutex_);
  twins_.push_back({key, out, frames, seconds, sc.name});
  twin_bytes_ += bytes(twins_.back());
  while (twin_bytes_ > kMaxTwinBytes) {
    const auto cheapest = std::min_element(twins_.begin(), twins_.end(), [&](const TwinEntry& a, const TwinEntry& b) {
      return a.seconds / static_cast<double>(bytes(a)) < b.seconds / static_cast<double>(bytes(b));
    });
    twin_bytes_ -= bytes(*cheapest);
    twins_.erase(cheapest);
  }
  return out;
}

}  // namespace hairbench
