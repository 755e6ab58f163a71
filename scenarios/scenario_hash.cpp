#include "scenarios/scenario.h"

#include "core/fnv64.h"

#include <cstdio>

namespace hairbench {

namespace {

void hash_groom(Fnv64& h, const Groom& g) {
  h.value(g.positions.size()).bytes(g.positions.data(), g.positions.size() * sizeof(Vec4f));
  h.value(g.strand_offsets.size()).bytes(g.strand_offsets.data(), g.strand_offsets.size() * sizeof(std::uint32_t));
  h.value(g.strand_region.size()).bytes(g.strand_region.data(), g.strand_region.size() * sizeof(std::uint16_t));
  for (const std::string& r : g.region_names) h.text(r);
  h.value(g.head_radius);
}

void hash_vec(Fnv64& h, const Vec3f& v) { h.value(v.x()).value(v.y()).value(v.z()); }

void hash_params(Fnv64& h, const std::map<std::string, double>& m) {
  h.value(m.size());
  for (const auto& [name, v] : m) h.text(name).value(v);
}

}  // namespace

std::string scenario_hash(const Scenario& sc, int frames) {
  Fnv64 h;
  h.text(sc.name).value(frames).value(sc.dt).value(sc.settle_from).text(sc.reference);
  hash_vec(h, sc.gravity);
  hash_groom(h, sc.groom);
  h.value(sc.follow.has_value());
  if (sc.follow) {
    hash_groom(h, sc.guides);
    const tfx::FollowHairs& f = *sc.follow;
    for (const auto* v : {&f.guide_offsets, &f.guide, &f.anchor, &f.follow_offsets})
      h.value(v->size()).bytes(v->data(), v->size() * sizeof(std::uint32_t));
    for (const Vec3f& o : f.offsets) hash_vec(h, o);
  }
  h.value(sc.region_params.size());
  for (const auto& r : sc.region_params) hash_params(h, r);
  h.value(sc.head_radius);
  for (const HeadKey& k : sc.head.keys) {
    h.value(k.t).value(k.angle).value(k.linear);
    hash_vec(h, k.translate);
    hash_vec(h, k.axis);
  }
  for (const Oscillator& o : sc.head.oscillators) {
    h.value(static_cast<int>(o.kind)).value(o.amplitude).value(o.frequency_hz).value(o.phase).value(o.start).value(o.end);
    hash_vec(h, o.axis);
  }
  for (const Sphere& c : sc.colliders) {
    hash_vec(h, c.center);
    h.value(c.radius).value(c.head_attached);
  }
  hash_vec(h, sc.wind.direction);
  h.value(sc.wind.strength);
  for (const WindScript::Key& k : sc.wind.keys) h.value(k.t).value(k.strength);
  for (const auto& [model, o] : sc.models) {
    h.text(model);
    hash_params(h, o.base);
    for (const auto& [region, values] : o.regions) {
      h.text(region);
      hash_params(h, values);
    }
  }
  h.value(sc.truth.has_value());
  if (sc.truth) {
    h.value(sc.truth->modes.size()).bytes(sc.truth->modes.data(), sc.truth->modes.size() * sizeof(int));
    h.value(sc.truth->amplitude);
    hash_vec(h, sc.truth->direction);
  }
  char b[17];
  std::snprintf(b, sizeof b, "%016llx", static_cast<unsigned long long>(h.digest()));
  return b;
}

}  // namespace hairbench
