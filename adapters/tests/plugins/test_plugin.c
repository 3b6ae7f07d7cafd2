/* A plugin in plain C99 for the loader's tests: free flight under the uniform field,
 * integrated exactly (x += v dt + g dt^2 / 2, v += g dt: exact for a constant
 * acceleration), so a gate with a closed-form expectation holds to round-off. Built
 * several times with TEST_PLUGIN_MODE choosing a misbehaviour:
 *   0 ballistic  the honest engine                 3 wrongabi  reports ABI version 99
 *   1 crashy     dereferences NULL at t >= 0.05 s  4 nanny     velocities turn NaN at t >= 0.05 s
 *   2 hangy      never returns from step at 0.05 s 5 failing   step reports an error at 0.05 s
 *   6 strained   reports a limit hit from 0.05 s on and a broken guarantee in the step that ends past 0.1 s
 *   7 liar       reports a contact with wall 99 (the scene has none) in the step that ends past 0.05 s
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "physval/plugin.h"

#ifndef TEST_PLUGIN_MODE
#define TEST_PLUGIN_MODE 0
#endif

#if TEST_PLUGIN_MODE == 0
#define NAME "ballistic"
#elif TEST_PLUGIN_MODE == 1
#define NAME "crashy"
#elif TEST_PLUGIN_MODE == 2
#define NAME "hangy"
#elif TEST_PLUGIN_MODE == 3
#define NAME "wrongabi"
#elif TEST_PLUGIN_MODE == 4
#define NAME "nanny"
#elif TEST_PLUGIN_MODE == 5
#define NAME "failing"
#elif TEST_PLUGIN_MODE == 6
#define NAME "strained"
#else
#define NAME "liar"
#endif

#define TROUBLE_AT 0.05

typedef struct body {
  physval_body_state s;
  double mass;
  double radius;
  char name[64];
} body;

struct physval_engine {
  body* bodies;
  size_t count;
  physval_vec2 g;
  double t;
  long long substeps;
  char substeps_text[32];
  physval_setting settings[2];
  char error[128];
};

static const physval_option_spec kOptions[] = {
    {"substeps", {PHYSVAL_OPTION_INT, 0, 1, 0.0, ""}, NULL, 0, "steps per physval step (the flight is exact at any)", 1.0,
     HUGE_VAL, 0},
};
static const physval_info kInfo = {
    NAME, "1.0", PHYSVAL_FLOAT64, "exact free flight in a uniform field (test plugin, C99)",
    PHYSVAL_FEATURE_BIT(PHYSVAL_FEATURE_CIRCLES) | PHYSVAL_FEATURE_BIT(PHYSVAL_FEATURE_POINTS) |
        PHYSVAL_FEATURE_BIT(PHYSVAL_FEATURE_UNIFORM_GRAVITY),
    kOptions, sizeof kOptions / sizeof kOptions[0]};

static const physval_info* info(void) { return &kInfo; }

static physval_engine* create(void) { return (physval_engine*)calloc(1, sizeof(physval_engine)); }

static void destroy(physval_engine* e) {
  free(e->bodies);
  free(e);
}

static const char* last_error(const physval_engine* e) { return e->error; }

static physval_status load(physval_engine* e, const physval_scene* s, const physval_host* host) {
  size_t i;
  (void)host;
  e->bodies = (body*)calloc(s->body_count > 0 ? s->body_count : 1, sizeof(body));
  if (e->bodies == NULL) {
    strcpy(e->error, "out of memory");
    return 1;
  }
  e->count = s->body_count;
  for (i = 0; i < s->body_count; ++i) {
    const physval_body* b = &s->bodies[i];
    body* o = &e->bodies[i];
    o->s.position = b->position;
    o->s.velocity = b->is_static ? (physval_vec2){0.0, 0.0} : b->velocity;
    o->s.angle = b->angle;
    o->s.alive = 1;
    o->mass = b->is_static ? 0.0 : b->mass;
    o->radius = b->radius;
    strncpy(o->name, b->name, sizeof o->name - 1);
  }
  e->g = s->world.gravity;
  e->t = 0.0;
  e->substeps = 1;
  for (i = 0; i < s->option_count; ++i) {
    if (strcmp(s->options[i].key, "substeps") == 0) e->substeps = (long long)s->options[i].value.i;
  }
  snprintf(e->substeps_text, sizeof e->substeps_text, "%lld", e->substeps);
  return 0;
}

static physval_status step(physval_engine* e, double dt) {
  size_t i;
  long long k;
  const double h = dt / (double)e->substeps;
  if (e->t >= TROUBLE_AT) {
#if TEST_PLUGIN_MODE == 1
    volatile int* volatile nowhere = NULL;
    *nowhere = 1;
#elif TEST_PLUGIN_MODE == 2
    volatile int forever = 1;
    while (forever) {
    }
#elif TEST_PLUGIN_MODE == 5
    /* Not UTF-8 (a Latin-1 "ü" and a stray byte): what a C library may well say. */
    strcpy(e->error, "the solver gave up (r\374ckw\344rts \377)");
    return 1;
#endif
  }
  for (k = 0; k < e->substeps; ++k) {
    for (i = 0; i < e->count; ++i) {
      body* b = &e->bodies[i];
      if (b->mass == 0.0) continue;
      b->s.position.x += b->s.velocity.x * h + 0.5 * e->g.x * h * h;
      b->s.position.y += b->s.velocity.y * h + 0.5 * e->g.y * h * h;
      b->s.velocity.x += e->g.x * h;
      b->s.velocity.y += e->g.y * h;
#if TEST_PLUGIN_MODE == 4
      if (e->t >= TROUBLE_AT) b->s.velocity.x = NAN;
#endif
    }
  }
  e->t += dt;
  return 0;
}

static double time_of(const physval_engine* e) { return e->t; }
static size_t body_count(const physval_engine* e) { return e->count; }

static physval_body_meta body_meta(const physval_engine* e, size_t i) {
  physval_body_meta m;
  m.name = e->bodies[i].name;
  m.mass = e->bodies[i].mass;
  m.radius = e->bodies[i].radius;
  m.is_static = e->bodies[i].mass == 0.0;
  return m;
}

static void read_states(const physval_engine* e, physval_body_state* out, size_t n) {
  size_t i;
  for (i = 0; i < n && i < e->count; ++i) out[i] = e->bodies[i].s;
}

static const physval_contact kNoSuchWall = {{PHYSVAL_OBJECT_BODY, 0}, {PHYSVAL_OBJECT_WALL, 99}, 0.06};

static void contacts(const physval_engine* e, const physval_contact** out, size_t* count) {
  *out = &kNoSuchWall;
  *count = TEST_PLUGIN_MODE == 7 && e->t > TROUBLE_AT ? 1 : 0;
}

static void settings(const physval_engine* e, const physval_setting** out, size_t* count) {
  physval_engine* m = (physval_engine*)e;
  m->settings[0].name = "integrator";
  m->settings[0].value = "exact constant-acceleration update";
  m->settings[1].name = "substeps";
  m->settings[1].value = m->substeps_text;
  *out = m->settings;
  *count = 2;
}

static const char* const kLimits[1] = {"speed clamp: a body was held at 100 m/s"};

static void limits_hit(const physval_engine* e, const char* const** out, size_t* count) {
  *out = kLimits;
  *count = TEST_PLUGIN_MODE == 6 && e->t >= TROUBLE_AT ? 1 : 0;
}

static const char* broken_guarantee(const physval_engine* e) {
  return TEST_PLUGIN_MODE == 6 && e->t > 2 * TROUBLE_AT + 1e-9 ? "event cap reached: impacts no longer exact" : "";
}

PHYSVAL_PLUGIN_EXPORT const physval_plugin_table_v1* physval_plugin_v1(uint32_t host_abi_version) {
  static physval_plugin_table_v1 t;
  (void)host_abi_version;
  t.abi_version = TEST_PLUGIN_MODE == 3 ? 99u : PHYSVAL_PLUGIN_ABI_VERSION;
  t.struct_size = sizeof t;
  t.info = info;
  t.create = create;
  t.destroy = destroy;
  t.last_error = last_error;
  t.load = load;
  t.step = step;
  t.time = time_of;
  t.body_count = body_count;
  t.body_meta = body_meta;
  t.read_states = read_states;
  t.contacts = contacts;
  t.settings = settings;
  t.limits_hit = limits_hit;
  t.broken_guarantee = broken_guarantee;
  return &t;
}
