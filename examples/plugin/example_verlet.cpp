// A minimal hairbench plugin (docs/plugins.md): strands as particle chains, Verlet
// integration under gravity, the edge lengths restored by a few Gauss-Seidel passes, the
// pinned vertices carried by the head. Everything it knows of hairbench is
// <hairbench/plugin.h>.
#include <hairbench/plugin.h>

#include <cmath>
#include <cstdio>
#include <new>
#include <vector>

namespace {

struct Model {
  const hb_host* host;
  std::vector<uint32_t> offsets;
  std::vector<float> rest, pos, prev, length;  // xyzw per vertex; length per vertex (edge into it)
  int iterations = 4;
  float damping = 0.02f;
};

const hb_param_spec kParams[] = {
    {"iterations", 4, 1, 64, 1, "edge-length passes per step", HB_ROLE_COST_KNOB, 0},
    {"damping", 0.02, 0, 1, 0, "share of the velocity lost per step", HB_ROLE_DAMPING, 0},
};

void* create(const hb_host* host, char* err, size_t err_size) {
  Model* m = new (std::nothrow) Model;
  if (!m) std::snprintf(err, err_size, "out of memory");
  else m->host = host;
  return m;
}

int reset(void* p, const hb_groom* g, const hb_params* params, const hb_initial_state* initial, char*, size_t) {
  Model& m = *static_cast<Model*>(p);
  m.offsets.assign(g->strand_offsets, g->strand_offsets + g->strand_count + 1);
  m.rest.assign(g->positions, g->positions + 4 * g->vertex_count);
  m.pos = m.prev = m.rest;
  m.length.assign(g->vertex_count, 0.0f);
  for (size_t s = 0; s < g->strand_count; ++s)
    for (uint32_t v = m.offsets[s] + 1; v < m.offsets[s + 1]; ++v) {
      const float* a = &m.rest[4 * (v - 1)];
      const float* b = &m.rest[4 * v];
      m.length[v] = std::sqrt((b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]) + (b[2] - a[2]) * (b[2] - a[2]));
    }
  // A kicked start (a truth scenario): these positions, at rest; w stays the groom's.
  if (initial && initial->positions)
    for (size_t i = 0; i < 4 * g->vertex_count; ++i)
      if (i % 4 != 3) m.pos[i] = m.prev[i] = initial->positions[i];
  m.iterations = static_cast<int>(params->base[0]);
  m.damping = static_cast<float>(params->base[1]);
  return HB_OK;
}

struct StepArgs {
  Model* m;
  const hb_frame* f;
};

void step_strands(void* user, size_t begin, size_t end) {
  const StepArgs& a = *static_cast<StepArgs*>(user);
  Model& m = *a.m;
  const float* h = a.f->head;  // column-major 4x4
  const float dt2 = static_cast<float>(a.f->dt * a.f->dt);
  for (size_t s = begin; s < end; ++s) {
    for (uint32_t v = m.offsets[s]; v < m.offsets[s + 1]; ++v) {
      float* x = &m.pos[4 * v];
      float* x0 = &m.prev[4 * v];
      const float* r = &m.rest[4 * v];
      for (int k = 0; k < 3; ++k) {
        const float next = r[3] == 0.0f ? h[k] * r[0] + h[4 + k] * r[1] + h[8 + k] * r[2] + h[12 + k]
                                        : x[k] + (1.0f - m.damping) * (x[k] - x0[k]) + a.f->gravity[k] * dt2;
        x0[k] = x[k];
        x[k] = next;
      }
    }
    for (int it = 0; it < m.iterations; ++it)
      for (uint32_t v = m.offsets[s] + 1; v < m.offsets[s + 1]; ++v) {
        float* p = &m.pos[4 * (v - 1)];
        float* q = &m.pos[4 * v];
        const float wp = m.rest[4 * (v - 1) + 3], wq = m.rest[4 * v + 3];
        if (wp + wq == 0.0f) continue;
        float d[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
        const float len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (len == 0.0f) continue;
        const float c = (len - m.length[v]) / (len * (wp + wq));
        for (int k = 0; k < 3; ++k) {
          p[k] += wp * c * d[k];
          q[k] -= wq * c * d[k];
        }
      }
  }
}

int step(void* p, const hb_frame* f, char*, size_t) {
  Model& m = *static_cast<Model*>(p);
  StepArgs args{&m, f};
  // By strand over the harness's threads: each strand is one thread's, so the bits do not
  // depend on the thread count.
  m.host->parallel_for(m.host->ctx, m.offsets.size() - 1, step_strands, &args);
  return HB_OK;
}

const float* positions(void* p, size_t* count) {
  const Model& m = *static_cast<Model*>(p);
  *count = m.pos.size() / 4;
  return m.pos.data();
}

void destroy(void* p) { delete static_cast<Model*>(p); }

const hb_model_desc kModels[] = {{"example_verlet", "example plugin: Verlet particle chains with Gauss-Seidel edge lengths",
                                  kParams, 2, 0.0, nullptr, create, reset, step, positions, destroy}};
const hb_plugin kPlugin = {HAIRBENCH_PLUGIN_ABI_VERSION, "example_verlet", kModels, 1};

}  // namespace

extern "C" HB_EXPORT const hb_plugin* hairbench_plugin(void) { return &kPlugin; }
