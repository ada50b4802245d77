/* The FMI 3.0 co-simulation functions of the test FMUs, written from the
 * FMI 3.0 specification (sections 2.2 and 4.2). Value references: Float64
 * 0..NF-1 (each of kSize[vr] elements), Int32 100.., Boolean 200..,
 * String 300... A model file defines, before including this file:
 *   MODEL_TOKEN, NF, NFV (all Float64 elements), NI, NB, NS,
 *   static const size_t kSize[NF];
 *   static void ModelDefaults(Model* m); static void ModelOutputs(Model* m);
 *   static fmi3Status ModelStep(Instance* c, double t, double h, bool* early, double* last,
 *                               bool* terminate); */
#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef void* fmi3Instance;
typedef void* fmi3InstanceEnvironment;
typedef void* fmi3FMUState;
typedef uint32_t fmi3ValueReference;
typedef double fmi3Float64;
typedef int32_t fmi3Int32;
typedef bool fmi3Boolean;
typedef char fmi3Char;
typedef const fmi3Char* fmi3String;
typedef uint8_t fmi3Byte;
typedef enum { fmi3OK, fmi3Warning, fmi3Discard, fmi3Error, fmi3Fatal } fmi3Status;
typedef void (*fmi3LogMessageCallback)(fmi3InstanceEnvironment, fmi3Status, fmi3String, fmi3String);
typedef void (*fmi3IntermediateUpdateCallback)(fmi3InstanceEnvironment, fmi3Float64, fmi3Boolean,
                                               fmi3Boolean, fmi3Boolean, fmi3Boolean,
                                               fmi3Boolean*, fmi3Float64*);

#define EXPORT __attribute__((visibility("default")))
#define STR_LEN 64

typedef struct {
  double f[NFV];
  int32_t i[NI > 0 ? NI : 1];
  bool b[NB > 0 ? NB : 1];
  char s[NS > 0 ? NS : 1][STR_LEN];
  double time;
  int started;
#ifdef MODEL_EXTRA_FIELDS
  MODEL_EXTRA_FIELDS
#endif
} Model;

typedef struct {
  Model m;
  fmi3InstanceEnvironment env;
  fmi3LogMessageCallback log;
  bool early_allowed; /* earlyReturnAllowed at instantiation */
} Instance;

static void ModelDefaults(Model* m);
static void ModelOutputs(Model* m);
static fmi3Status ModelStep(Instance* c, double t, double h, bool* early, double* last,
                            bool* terminate);

static size_t Offset(fmi3ValueReference vr) {
  size_t o = 0;
  for (fmi3ValueReference k = 0; k < vr; ++k) o += kSize[k];
  return o;
}

EXPORT const char* fmi3GetVersion(void) { return "3.0"; }

EXPORT fmi3Instance fmi3InstantiateCoSimulation(
    fmi3String name, fmi3String token, fmi3String resources, fmi3Boolean visible,
    fmi3Boolean logging, fmi3Boolean event_mode, fmi3Boolean early_allowed,
    const fmi3ValueReference required[], size_t n_required, fmi3InstanceEnvironment env,
    fmi3LogMessageCallback log, fmi3IntermediateUpdateCallback update) {
  (void)name; (void)resources; (void)visible; (void)logging;
  (void)required; (void)n_required; (void)update;
  if (strcmp(token, MODEL_TOKEN) != 0 || event_mode) return NULL;
  Instance* c = (Instance*)calloc(1, sizeof(Instance));
  c->env = env;
  c->log = log;
  c->early_allowed = early_allowed;
  ModelDefaults(&c->m);
  if (log) log(env, fmi3OK, "logEvents", "instantiated " MODEL_TOKEN);
  return c;
}
EXPORT void fmi3FreeInstance(fmi3Instance c) { free(c); }
EXPORT fmi3Status fmi3EnterInitializationMode(fmi3Instance c, fmi3Boolean tol_defined, fmi3Float64 tol,
                                              fmi3Float64 start, fmi3Boolean stop_defined, fmi3Float64 stop) {
  (void)tol_defined; (void)tol; (void)stop_defined; (void)stop;
  ((Instance*)c)->m.time = start;
  return fmi3OK;
}
EXPORT fmi3Status fmi3ExitInitializationMode(fmi3Instance c) { (void)c; return fmi3OK; }
EXPORT fmi3Status fmi3Terminate(fmi3Instance c) {
  /* Logged, so that tests see which call sequences an importer made. */
  Instance* ci = (Instance*)c;
  if (ci->log) ci->log(ci->env, fmi3OK, "logEvents", "fmi3Terminate called");
  return fmi3OK;
}

EXPORT fmi3Status fmi3GetFloat64(fmi3Instance c, const fmi3ValueReference vr[], size_t n,
                                 fmi3Float64 v[], size_t nv) {
  Model* m = &((Instance*)c)->m;
  ModelOutputs(m);
  size_t at = 0;
  for (size_t k = 0; k < n; ++k) {
    if (vr[k] >= NF || at + kSize[vr[k]] > nv) return fmi3Error;
    memcpy(v + at, m->f + Offset(vr[k]), kSize[vr[k]] * sizeof(double));
    at += kSize[vr[k]];
  }
  return at == nv ? fmi3OK : fmi3Error;
}
EXPORT fmi3Status fmi3SetFloat64(fmi3Instance c, const fmi3ValueReference vr[], size_t n,
                                 const fmi3Float64 v[], size_t nv) {
  Model* m = &((Instance*)c)->m;
  size_t at = 0;
  for (size_t k = 0; k < n; ++k) {
    if (vr[k] >= NF || at + kSize[vr[k]] > nv) return fmi3Error;
    memcpy(m->f + Offset(vr[k]), v + at, kSize[vr[k]] * sizeof(double));
    at += kSize[vr[k]];
  }
  return at == nv ? fmi3OK : fmi3Error;
}
#define CHECK3(base, count)                                                   \
  if (n != nv) return fmi3Error;                                              \
  for (size_t k = 0; k < n; ++k)                                              \
    if ((long)vr[k] < (long)(base) || (long)vr[k] >= (long)(base) + (long)(count)) return fmi3Error;

EXPORT fmi3Status fmi3GetInt32(fmi3Instance c, const fmi3ValueReference vr[], size_t n, fmi3Int32 v[], size_t nv) {
  Model* m = &((Instance*)c)->m;
  CHECK3(100, NI)
  ModelOutputs(m);
  for (size_t k = 0; k < n; ++k) v[k] = m->i[vr[k] - 100];
  return fmi3OK;
}
EXPORT fmi3Status fmi3SetInt32(fmi3Instance c, const fmi3ValueReference vr[], size_t n, const fmi3Int32 v[], size_t nv) {
  Model* m = &((Instance*)c)->m;
  CHECK3(100, NI)
  for (size_t k = 0; k < n; ++k) m->i[vr[k] - 100] = v[k];
  return fmi3OK;
}
EXPORT fmi3Status fmi3GetBoolean(fmi3Instance c, const fmi3ValueReference vr[], size_t n, fmi3Boolean v[], size_t nv) {
  Model* m = &((Instance*)c)->m;
  CHECK3(200, NB)
  ModelOutputs(m);
  for (size_t k = 0; k < n; ++k) v[k] = m->b[vr[k] - 200];
  return fmi3OK;
}
EXPORT fmi3Status fmi3SetBoolean(fmi3Instance c, const fmi3ValueReference vr[], size_t n, const fmi3Boolean v[], size_t nv) {
  Model* m = &((Instance*)c)->m;
  CHECK3(200, NB)
  for (size_t k = 0; k < n; ++k) m->b[vr[k] - 200] = v[k];
  return fmi3OK;
}
EXPORT fmi3Status fmi3GetString(fmi3Instance c, const fmi3ValueReference vr[], size_t n, fmi3String v[], size_t nv) {
  Model* m = &((Instance*)c)->m;
  CHECK3(300, NS)
  ModelOutputs(m);
  for (size_t k = 0; k < n; ++k) v[k] = m->s[vr[k] - 300];
  return fmi3OK;
}
EXPORT fmi3Status fmi3SetString(fmi3Instance c, const fmi3ValueReference vr[], size_t n, const fmi3String v[], size_t nv) {
  Model* m = &((Instance*)c)->m;
  CHECK3(300, NS)
  for (size_t k = 0; k < n; ++k) {
    strncpy(m->s[vr[k] - 300], v[k] ? v[k] : "", STR_LEN - 1);
    m->s[vr[k] - 300][STR_LEN - 1] = 0;
  }
  return fmi3OK;
}

EXPORT fmi3Status fmi3DoStep(fmi3Instance c, fmi3Float64 t, fmi3Float64 h, fmi3Boolean no_set_prior,
                             fmi3Boolean* event_needed, fmi3Boolean* terminate, fmi3Boolean* early,
                             fmi3Float64* last) {
  (void)no_set_prior;
  Instance* ci = (Instance*)c;
  *event_needed = false;
  *terminate = false;
  *early = false;
  *last = t + h;
  ModelOutputs(&ci->m);
  ci->m.started = 1;
  return ModelStep(ci, t, h, early, last, terminate);
}

EXPORT fmi3Status fmi3GetFMUState(fmi3Instance c, fmi3FMUState* s) {
  Model* copy = (Model*)malloc(sizeof(Model));
  *copy = ((Instance*)c)->m;
  *s = copy;
  return fmi3OK;
}
EXPORT fmi3Status fmi3SetFMUState(fmi3Instance c, fmi3FMUState s) {
  ((Instance*)c)->m = *(Model*)s;
  return fmi3OK;
}
EXPORT fmi3Status fmi3FreeFMUState(fmi3Instance c, fmi3FMUState* s) {
  (void)c;
  free(*s);
  *s = NULL;
  return fmi3OK;
}
EXPORT fmi3Status fmi3SerializedFMUStateSize(fmi3Instance c, fmi3FMUState s, size_t* size) {
  (void)c; (void)s;
  *size = sizeof(Model);
  return fmi3OK;
}
EXPORT fmi3Status fmi3SerializeFMUState(fmi3Instance c, fmi3FMUState s, fmi3Byte b[], size_t size) {
  (void)c;
  if (size != sizeof(Model)) return fmi3Error;
  memcpy(b, s, sizeof(Model));
  return fmi3OK;
}
EXPORT fmi3Status fmi3DeserializeFMUState(fmi3Instance c, const fmi3Byte b[], size_t size, fmi3FMUState* s) {
  (void)c;
  if (size != sizeof(Model)) return fmi3Error;
  Model* copy = (Model*)malloc(sizeof(Model));
  memcpy(copy, b, sizeof(Model));
  *s = copy;
  return fmi3OK;
}
