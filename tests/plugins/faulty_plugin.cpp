// A plugin that fails in one chosen way (FAULT, set per library by tests/CMakeLists.txt),
// for tests/plugin_test.cpp: the harness must turn each failure into one line and exit 2
// (at load) or into its run's `diverged` verdict (at run time), never a crash.
//
// Its model holds the hair rigidly with the head (every vertex at head * rest): a model
// that is trivially right until its fault.
#include <hairbench/plugin.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

#define FAULT_NONE 0
#define FAULT_ABI 1      // built for another ABI version
#define FAULT_NAN 2      // positions turn NaN at frame 5
#define FAULT_THROW 3    // step throws a C++ exception across the boundary at frame 5
#define FAULT_COUNT 4    // returns one position too few
#define FAULT_STATUS 5   // step returns HB_ERROR with a message at frame 5

#ifndef FAULT
#error "FAULT must be defined"
#endif

namespace {

struct Rigid {
  std::vector<float> rest, pos;
};

void* create(const hb_host*, char*, size_t) { return new Rigid; }

int reset(void* m, const hb_groom* g, const hb_params*, const hb_initial_state*, char*, size_t) {
  auto* r = static_cast<Rigid*>(m);
  r->rest.assign(g->positions, g->positions + 4 * g->vertex_count);
  r->pos = r->rest;
  return HB_OK;
}

int step(void* m, const hb_frame* f, char* err, size_t err_size) {
  auto* r = static_cast<Rigid*>(m);
  if (FAULT == FAULT_THROW && f->frame == 5) throw std::runtime_error("the faulty plugin's planted exception");
  if (FAULT == FAULT_STATUS && f->frame == 5) {
    std::snprintf(err, err_size, "the faulty plugin's planted error at frame %d", f->frame);
    return HB_ERROR;
  }
  const float* h = f->head;  // column-major 4x4
  for (size_t v = 0; 4 * v < r->rest.size(); ++v) {
    const float* p = &r->rest[4 * v];
    for (int k = 0; k < 3; ++k) r->pos[4 * v + k] = h[k] * p[0] + h[4 + k] * p[1] + h[8 + k] * p[2] + h[12 + k];
  }
  if (FAULT == FAULT_NAN && f->frame >= 5) r->pos[4 * (r->rest.size() / 8)] = std::nanf("");
  return HB_OK;
}

const float* positions(void* m, size_t* count) {
  auto* r = static_cast<Rigid*>(m);
  *count = r->pos.size() / 4 - (FAULT == FAULT_COUNT ? 1 : 0);
  return r->pos.data();
}

void destroy(void* m) { delete static_cast<Rigid*>(m); }

const hb_model_desc kModels[] = {{MODEL_NAME, "a rigid model with a planted fault (tests/plugins/faulty_plugin.cpp)",
                                  nullptr, 0, 0.0, nullptr, create, reset, step, positions, destroy}};

const hb_plugin kPlugin = {FAULT == FAULT_ABI ? HAIRBENCH_PLUGIN_ABI_VERSION + 1 : HAIRBENCH_PLUGIN_ABI_VERSION,
                           MODEL_NAME, kModels, 1};

}  // namespace

extern "C" HB_EXPORT const hb_plugin* hairbench_plugin(void) { return &kPlugin; }
