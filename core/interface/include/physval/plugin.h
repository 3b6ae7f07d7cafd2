/* physval engine plugin ABI, version 1.
 *
 * One header, plain C99 (usable from C++), needing nothing else of physval. A plugin is a
 * shared library that exports ONE function:
 *
 *     PHYSVAL_PLUGIN_EXPORT const physval_plugin_table_v1* physval_plugin_v1(uint32_t host_abi);
 *
 * physval calls it with PHYSVAL_PLUGIN_ABI_VERSION; the plugin returns a pointer to a
 * static function table whose `abi_version` is the PHYSVAL_PLUGIN_ABI_VERSION it was
 * compiled with (or NULL when it cannot serve that host). physval refuses a table whose
 * version differs from its own, with a message naming both versions: a mismatch is an
 * error, never a crash.
 *
 * The scene reaches the plugin as plain C structs (arrays with counts), a mirror of
 * physval's own scene model: every key of a scenario file, already validated and with
 * every default applied. All pointers handed to the plugin stay valid during the call
 * only (copy what you keep). Strings are UTF-8, NUL-terminated, never NULL ("" when
 * empty). Units are SI (m, kg, s), angles in radians.
 *
 * Strings and arrays the plugin returns (info, settings, limits, contacts, errors) must
 * stay valid until the next call on the same engine (or, for the info, for the life of
 * the library).
 *
 * Threads: physval runs each scenario in a child process and calls one engine from one
 * thread; different engines may live in one process in sequence, never concurrently.
 */
#ifndef PHYSVAL_PLUGIN_H
#define PHYSVAL_PLUGIN_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define PHYSVAL_PLUGIN_ABI_VERSION 1u
#define PHYSVAL_PLUGIN_ENTRY_POINT "physval_plugin_v1"

#if defined(_WIN32)
#define PHYSVAL_PLUGIN_EXPORT __declspec(dllexport)
#else
#define PHYSVAL_PLUGIN_EXPORT __attribute__((visibility("default")))
#endif

/* ------------------------------------------------------------------ features */

/* The scenario models a plugin can declare (bit 1 << feature in physval_info.features).
 * The numbering is the ABI: new features are only ever appended. A scenario that uses
 * a feature the plugin does not declare is reported `unsupported` without loading it. */
typedef enum physval_feature {
  PHYSVAL_FEATURE_CIRCLES = 0,
  PHYSVAL_FEATURE_POINTS = 1,
  PHYSVAL_FEATURE_STATIC_BODIES = 2,
  PHYSVAL_FEATURE_WALLS = 3,
  PHYSVAL_FEATURE_BOXES = 4,
  PHYSVAL_FEATURE_SURFACES = 5,
  PHYSVAL_FEATURE_UNIFORM_GRAVITY = 6,
  PHYSVAL_FEATURE_NEWTONIAN_GRAVITY = 7,
  PHYSVAL_FEATURE_LINEAR_DRAG = 8,
  PHYSVAL_FEATURE_QUADRATIC_DRAG = 9,
  PHYSVAL_FEATURE_WIND = 10,
  PHYSVAL_FEATURE_THRUST = 11,
  PHYSVAL_FEATURE_FRICTION = 12,
  PHYSVAL_FEATURE_STATIC_FRICTION = 13, /* mu_s > mu_k somewhere */
  PHYSVAL_FEATURE_ROLLING_FRICTION = 14,
  PHYSVAL_FEATURE_MATERIAL_OVERRIDES = 15,
  PHYSVAL_FEATURE_COLLISION_MATRIX = 16,
  PHYSVAL_FEATURE_PARTICLES = 17,
  PHYSVAL_FEATURE_SURFACE_NORMALS = 18,
  PHYSVAL_FEATURE_COUNT = 19
} physval_feature;

#define PHYSVAL_FEATURE_BIT(f) ((uint64_t)1 << (unsigned)(f))

/* ------------------------------------------------------------------- options */

/* An option of the plugin's own scenario table `[<plugin name>]`. physval validates the
 * scenario against these declarations (`physval check`: file:line:key, exit 2) and
 * hands the plugin every declared option, given or defaulted, at load. */
typedef enum physval_option_type {
  PHYSVAL_OPTION_BOOL = 0,
  PHYSVAL_OPTION_INT = 1,
  PHYSVAL_OPTION_DOUBLE = 2,
  PHYSVAL_OPTION_STRING = 3
} physval_option_type;

typedef struct physval_option_value {
  physval_option_type type; /* which member below holds the value */
  int b;                    /* BOOL: 0 or 1 */
  int64_t i;                /* INT */
  double d;                 /* DOUBLE (an INT given for a DOUBLE option is widened) */
  const char* s;            /* STRING */
} physval_option_value;

typedef struct physval_option_spec {
  const char* key;                    /* [a-z0-9_]+ */
  physval_option_value default_value; /* its type is the option's type */
  const char* const* choices;         /* STRING: the allowed values (NULL: any) */
  size_t choice_count;
  const char* doc;                    /* one line */
  /* INT and DOUBLE: the accepted values, lo <= v <= hi (lo < v when lo_open). Use
   * -HUGE_VAL / HUGE_VAL for no bound. */
  double range_lo;
  double range_hi;
  int range_lo_open;
} physval_option_spec;

typedef struct physval_option {
  const char* key;
  physval_option_value value;
} physval_option;

/* ---------------------------------------------------------------------- info */

typedef enum physval_precision { PHYSVAL_FLOAT32 = 0, PHYSVAL_FLOAT64 = 1 } physval_precision;

typedef struct physval_info {
  const char* name;      /* [a-z0-9_]+, unique among engines: names its option table */
  const char* version;   /* the engine's version */
  physval_precision precision;
  const char* summary;   /* one line: what it is */
  uint64_t features;     /* OR of PHYSVAL_FEATURE_BIT(...) */
  const physval_option_spec* options;
  size_t option_count;
} physval_info;

/* --------------------------------------------------------------------- scene */

typedef struct physval_vec2 {
  double x;
  double y;
} physval_vec2;

typedef enum physval_shape { PHYSVAL_SHAPE_CIRCLE = 0, PHYSVAL_SHAPE_POINT = 1 } physval_shape;

/* a(speed[, gear]) in m/s^2, piecewise linear between samples and clamped at the ends,
 * times the throttle, along the body's heading. Disabled when speed_count == 0. */
typedef struct physval_thrust {
  const double* speeds; /* strictly increasing, m/s */
  size_t speed_count;
  const double* gears;  /* strictly increasing; gear_count 0: one-input table */
  size_t gear_count;
  const double* accel;  /* row-major: max(gear_count, 1) rows of speed_count values */
  double throttle;
  double gear;
} physval_thrust;

typedef struct physval_body {
  const char* name;
  physval_shape shape;
  double radius;            /* circles > 0, points 0 */
  double mass;              /* > 0 (ignored when is_static) */
  int is_static;
  physval_vec2 position;
  physval_vec2 velocity;
  double angle;             /* heading, rad */
  double angular_velocity;  /* rad/s */
  double restitution;
  double friction;          /* kinetic Coulomb coefficient */
  double static_friction;   /* >= friction */
  double rolling_friction;  /* rolling-resistance coefficient: F = c N */
  double drag_linear;       /* F = -k1 (v - wind) */
  double drag_quadratic;    /* F = -k2 |v - wind| (v - wind) */
  const char* group;        /* collision-matrix group, "" = default */
  physval_thrust thrust;
} physval_body;

typedef struct physval_material {
  double restitution;
  double friction;
  double static_friction;
  double rolling_friction;
  const char* group;
} physval_material;

/* An immovable segment; circles collide with it on both sides and at its ends. */
typedef struct physval_wall {
  const char* name;
  physval_vec2 from;
  physval_vec2 to;
  physval_material material;
} physval_wall;

/* An immovable axis-aligned box. */
typedef struct physval_box {
  const char* name;
  physval_vec2 min;
  physval_vec2 max;
  physval_material material;
} physval_box;

/* An open polyline; with normals (one unit normal per point, interpolated along each
 * segment) a bounce uses them instead of the segments' geometric normals. */
typedef struct physval_surface {
  const char* name;
  const physval_vec2* points;
  size_t point_count;          /* >= 2 */
  const physval_vec2* normals; /* NULL, or point_count of them */
  physval_material material;
} physval_surface;

/* A per-pair override by body or barrier name; has_* says which fields are given. */
typedef struct physval_material_override {
  const char* a;
  const char* b;
  int has_restitution;
  double restitution;
  int has_friction;
  double friction;
  int has_static_friction;
  double static_friction;
  int has_rolling_friction;
  double rolling_friction;
} physval_material_override;

typedef enum physval_response {
  PHYSVAL_RESPONSE_BOUNCE = 0,
  PHYSVAL_RESPONSE_DESTROY_A = 1,
  PHYSVAL_RESPONSE_DESTROY_B = 2,
  PHYSVAL_RESPONSE_DESTROY_BOTH = 3,
  PHYSVAL_RESPONSE_IGNORE = 4,
  PHYSVAL_RESPONSE_EVENT = 5
} physval_response;

typedef struct physval_collision_rule {
  const char* a; /* group */
  const char* b; /* group */
  physval_response response;
} physval_collision_rule;

typedef enum physval_emitter_mode { PHYSVAL_EMITTER_EXPLODE = 0, PHYSVAL_EMITTER_TRAIL = 1 } physval_emitter_mode;

typedef struct physval_emitter {
  const char* name;
  const char* parent;   /* body name */
  physval_emitter_mode mode;
  double at;            /* explode: when the parent explodes (it is destroyed) */
  double rate;          /* trail: particles per second while the parent lives */
  int count;            /* explode: how many */
  double speed;         /* velocities uniform in a disc of this radius around the parent's */
  double lifetime;      /* s */
  double mass;          /* kg per particle */
  int destroy_on_collision;
  int gravity;          /* particles feel the uniform field */
  uint64_t seed;
} physval_emitter;

typedef struct physval_world {
  physval_vec2 gravity;
  int newtonian;        /* F = G m1 m2 / (D^2 + softening^2) between all bodies */
  double G;
  double softening;
  physval_vec2 wind;
} physval_world;

typedef struct physval_scene {
  const char* name;
  const char* source_file;
  double duration;      /* s */
  double dt;            /* the scenario's step (physval passes each step's dt to step()) */
  physval_world world;
  const physval_body* bodies;
  size_t body_count;
  const physval_wall* walls;
  size_t wall_count;
  const physval_box* boxes;
  size_t box_count;
  const physval_surface* surfaces;
  size_t surface_count;
  const physval_material_override* materials;
  size_t material_count;
  const physval_collision_rule* collision_rules;
  size_t collision_rule_count;
  const physval_emitter* emitters;
  size_t emitter_count;
  /* The plugin's own options: every option it declared, in declaration order, with the
   * scenario's value or the default. */
  const physval_option* options;
  size_t option_count;
} physval_scene;

/* ------------------------------------------------------------ host services */

/* physval's shared rules, so a plugin applies exactly what every other engine applies
 * instead of re-implementing them. */
typedef struct physval_material_view {
  const char* name;   /* body or barrier name (overrides are by name) */
  double restitution;
  double friction;
  double static_friction;
  double rolling_friction;
} physval_material_view;

typedef struct physval_pair_material {
  double restitution;
  double friction;
  double static_friction;
  double rolling_friction;
} physval_pair_material;

typedef struct physval_pair_response {
  int collide;          /* resolve the impact (bounce) */
  int event;            /* raise a contact event */
  int destroy_first;
  int destroy_second;
} physval_pair_response;

typedef struct physval_host {
  uint32_t abi_version; /* PHYSVAL_PLUGIN_ABI_VERSION of the host */
  void* context;        /* pass back to the functions below */
  /* The pair's material: restitution the smaller of the two, friction coefficients the
   * geometric mean, unless the scenario overrides the pair by name. */
  physval_pair_material (*combine_materials)(void* context, const physval_material_view* a,
                                             const physval_material_view* b);
  /* What the collision matrix says happens when group_first meets group_second. */
  physval_pair_response (*response_between)(void* context, const char* group_first, const char* group_second);
} physval_host;

/* ------------------------------------------------------------------- results */

typedef struct physval_body_state {
  physval_vec2 position;
  physval_vec2 velocity;
  double angle;
  double angular_velocity;
  int alive;            /* 0 once destroyed (collision matrix, particle death) */
} physval_body_state;

/* A body the scene did not list (a particle); for i < body_count of the scene it is the
 * scene's body i. */
typedef struct physval_body_meta {
  const char* name;
  double mass;          /* 0 for static bodies */
  double radius;
  int is_static;
} physval_body_meta;

typedef enum physval_object_kind {
  PHYSVAL_OBJECT_BODY = 0,    /* scene bodies in order, then particles in order of creation */
  PHYSVAL_OBJECT_WALL = 1,
  PHYSVAL_OBJECT_BOX = 2,
  PHYSVAL_OBJECT_SURFACE = 3
} physval_object_kind;

typedef struct physval_object_ref {
  physval_object_kind kind;
  uint32_t index;
} physval_object_ref;

/* A contact that began during the last step at simulated time `time` (an exact impact
 * time, or the end of the step). `a` is always a body; two bodies are ordered by index. */
typedef struct physval_contact {
  physval_object_ref a;
  physval_object_ref b;
  double time;
} physval_contact;

typedef struct physval_setting {
  const char* name;
  const char* value;    /* printable */
} physval_setting;

/* -------------------------------------------------------------- the table */

typedef struct physval_engine physval_engine; /* the plugin's own, opaque to physval */

/* Status of the calls that can fail: 0 = success; anything else = failure, with the
 * text in last_error(). A failed load or step ends the run with status `error`. */
typedef int physval_status;

typedef struct physval_plugin_table_v1 {
  uint32_t abi_version;   /* PHYSVAL_PLUGIN_ABI_VERSION the plugin was compiled with */
  uint32_t struct_size;   /* sizeof(physval_plugin_table_v1) */

  const physval_info* (*info)(void);

  /* A fresh engine, or NULL when out of memory. */
  physval_engine* (*create)(void);
  void (*destroy)(physval_engine* e);

  /* Why the last failing call failed (never NULL; "" when nothing failed). */
  const char* (*last_error)(const physval_engine* e);

  /* Builds the world. `host` stays valid until destroy(). */
  physval_status (*load)(physval_engine* e, const physval_scene* scene, const physval_host* host);
  /* Advances by dt seconds (dt may change from call to call; the last step is shorter). */
  physval_status (*step)(physval_engine* e, double dt);

  double (*time)(const physval_engine* e);   /* simulated seconds since load */

  /* Bodies so far: the scene's, then particles; destroyed ones stay (alive = 0). */
  size_t (*body_count)(const physval_engine* e);
  physval_body_meta (*body_meta)(const physval_engine* e, size_t i);
  /* Fills out[0 .. n), n == body_count(e). */
  void (*read_states)(const physval_engine* e, physval_body_state* out, size_t n);

  /* Contacts that began during the last step: *out points at *count of them. */
  void (*contacts)(const physval_engine* e, const physval_contact** out, size_t* count);

  /* The settings this run actually uses (after defaults and the scenario's options),
   * written into results.json so every run explains itself. */
  void (*settings)(const physval_engine* e, const physval_setting** out, size_t* count);

  /* Limits the engine imposed so far (a speed clamp hit, ...): one line each. */
  void (*limits_hit)(const physval_engine* e, const char* const** out, size_t* count);

  /* A guarantee the engine could not keep during the last step: "" while all hold.
   * physval then stops the run and reports it `diverged` with this text. */
  const char* (*broken_guarantee)(const physval_engine* e);
} physval_plugin_table_v1;

typedef const physval_plugin_table_v1* (*physval_plugin_v1_fn)(uint32_t host_abi_version);

/* The one function a plugin defines and exports. */
PHYSVAL_PLUGIN_EXPORT const physval_plugin_table_v1* physval_plugin_v1(uint32_t host_abi_version);

#ifdef __cplusplus
}
#endif

#endif /* PHYSVAL_PLUGIN_H */
