/* hairbench plugin ABI, version 1 (docs/plugins.md).
 *
 * A shared library provides one or more hair models to `hairbench` through one C entry
 * point, `hairbench_plugin`, that returns a static description. The harness loads the
 * library (`hairbench compare --plugin PATH.so`, or every library on HAIRBENCH_PLUGIN_PATH),
 * checks `abi_version` before it reads anything else, and then runs each model exactly as it
 * runs a built-in one: every scenario, metric, verdict, sweep, shard and report applies.
 *
 * Plain C, so that a plugin may be written in C, C++ or anything that exports a C symbol,
 * and built with another compiler than the harness. Every function returns an HB_OK/HB_ERROR
 * status and writes a one-line message on error; an exception must not leave a function
 * (the harness catches one that does and fails the run, but it is undefined behaviour in C
 * terms). A plugin runs in the harness's process: one that corrupts memory can crash it.
 *
 * Units: metres, seconds, radians. Positions are float x, y, z, w per vertex, strand-major;
 * w of the rest groom is the inverse mass, 0 for a vertex pinned to the head.
 */
#ifndef HAIRBENCH_PLUGIN_H
#define HAIRBENCH_PLUGIN_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Raised on any change to a struct or function below; the harness refuses another. */
#define HAIRBENCH_PLUGIN_ABI_VERSION 1u

/* The entry point's name, and its type: `HB_EXPORT const hb_plugin* hairbench_plugin(void);` */
#define HAIRBENCH_PLUGIN_ENTRY "hairbench_plugin"

#if defined(_WIN32)
#define HB_EXPORT __declspec(dllexport)
#else
#define HB_EXPORT __attribute__((visibility("default")))
#endif

enum { HB_OK = 0, HB_ERROR = 1 };

/* What a parameter sets, for the harness's runs that need to know: --calibrate fits the
 * stiffness and reports the damping; work-precision runs walk the cost knobs; ground-truth
 * runs switch a model's chain-limit parameters to their chain limit. */
typedef enum hb_param_role {
  HB_ROLE_NONE = 0,
  HB_ROLE_STIFFNESS = 1,
  HB_ROLE_DAMPING = 2,
  HB_ROLE_COST_KNOB = 3,   /* more of it costs more and converges: substeps, iterations */
  HB_ROLE_CHAIN_LIMIT = 4  /* set to `chain_value` it turns the bending/shape terms off */
} hb_param_role;

typedef struct hb_param_spec {
  const char* name;  /* [a-z0-9_]+, unique within the model */
  double default_value;
  double min, max;   /* the harness refuses values outside [min, max] */
  int integer;       /* nonzero: whole numbers only */
  const char* help;  /* one line, with the unit and the paper's symbol */
  int role;          /* hb_param_role */
  double chain_value; /* HB_ROLE_CHAIN_LIMIT: the value that turns the term off */
} hb_param_spec;

/* The rest groom, in the head's rest frame. Valid for the duration of reset(). */
typedef struct hb_groom {
  size_t strand_count;
  const uint32_t* strand_offsets; /* strand_count + 1 entries; strand s owns [o[s], o[s+1]) */
  size_t vertex_count;
  const float* positions;         /* vertex_count * 4: x, y, z, inverse mass */
  const uint16_t* strand_region;  /* strand_count entries, indices into the regions */
  size_t region_count;
  float head_radius;
} hb_groom;

/* The resolved parameters, in the order of the model's hb_param_spec array: base values,
 * then one row per region (a region's value is its override where it has one). */
typedef struct hb_params {
  size_t count;                /* the model's param_count */
  const double* base;          /* count values */
  size_t region_count;
  const double* region_values; /* region_count * count values, row-major by region */
} hb_params;

/* An initial state other than rest (a kicked strand): positions and velocities per
 * vertex, world space, the same layout as the groom; either pointer may be NULL (rest,
 * at rest). */
typedef struct hb_initial_state {
  const float* positions;  /* vertex_count * 4; w ignored */
  const float* velocities; /* vertex_count * 4; w ignored */
} hb_initial_state;

/* One step's input: the head at both ends of the step and what acts on the hair. */
typedef struct hb_frame {
  int32_t frame;            /* index of the step, 0-based */
  double t;                 /* time at the end of the step */
  double dt;                /* step length */
  float head_prev[16];      /* head rest -> world at t - dt, 4x4 column-major */
  float head[16];           /* head rest -> world at t */
  float gravity[3];         /* m/s^2, world */
  float rest_gravity[3];    /* gravity as the head sees it at rest (what a head-fixed offset reads) */
  float wind[3];            /* acceleration, m/s^2, world; zero when there is none */
  const float* spheres;     /* sphere_count * 4: centre x, y, z (world, at t) and radius */
  size_t sphere_count;
} hb_frame;

/* The solver stages a step may time (the report's timing.stages keys). */
typedef enum hb_stage {
  HB_STAGE_INTEGRATE = 0,
  HB_STAGE_LENGTH = 1,
  HB_STAGE_COLLISION = 2,
  HB_STAGE_SHAPE = 3,  /* reported as local_shape */
  HB_STAGE_COUNT = 4
} hb_stage;

/* What the harness hands a model when it creates it. */
typedef struct hb_host {
  void* ctx;
  /* Calls fn(user, begin, end) over a static partition of [0, count) on the harness's
   * worker threads and returns when all are done: work split by strand through it is
   * bit-identical at any --threads, and timed as the built-in models' is. */
  void (*parallel_for)(void* ctx, size_t count, void (*fn)(void* user, size_t begin, size_t end), void* user);
  /* Adds `ms` of wall time to a stage of the current step (optional to call). */
  void (*stage_time)(void* ctx, int stage, double ms);
  int threads;      /* the worker count parallel_for splits over */
  int skip_inert;   /* 0: run every stage even where it is inert (hairbench --no-skip) */
} hb_host;

typedef struct hb_model_desc {
  const char* name;    /* [a-z0-9_]+; must not clash with a built-in or another plugin's model */
  const char* summary; /* one line, with the paper and the sections it implements */
  const hb_param_spec* params;
  size_t param_count;
  /* The step's cost, for sharding a sweep: ns per vertex and step at the defaults on
   * `shake` (2,000 strands of 16 vertices), median, 2 threads on a 2-core x86-64 machine
   * as the built-in models' costs are, and the parameter the whole step scales with
   * (substeps), or NULL. 0: unknown (costed as the slowest model, and the plan says so). */
  double cost_ns_per_vertex;
  const char* cost_multiplier;

  /* A new model, not yet reset; NULL on failure (with a message in err). */
  void* (*create)(const hb_host* host, char* err, size_t err_size);
  /* To the rest groom with the resolved parameters; the hair starts at rest under the
   * identity head transform, or in `initial` (may be NULL). */
  int (*reset)(void* model, const hb_groom* rest, const hb_params* params, const hb_initial_state* initial,
               char* err, size_t err_size);
  /* Advances by frame->dt. */
  int (*step)(void* model, const hb_frame* frame, char* err, size_t err_size);
  /* The current positions, the rest groom's layout (vertex_count * 4 floats), valid until
   * the next step or reset; *vertex_count is set to their count. */
  const float* (*positions)(void* model, size_t* vertex_count);
  void (*destroy)(void* model);
} hb_model_desc;

typedef struct hb_plugin {
  uint32_t abi_version; /* HAIRBENCH_PLUGIN_ABI_VERSION; read before anything else */
  const char* name;     /* the library's name, for messages */
  const hb_model_desc* models;
  size_t model_count;
} hb_plugin;

typedef const hb_plugin* (*hb_plugin_entry)(void);

#ifdef __cplusplus
}
#endif

#endif /* HAIRBENCH_PLUGIN_H */
