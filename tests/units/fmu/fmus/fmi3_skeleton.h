/* The FMI 3.0 co-simulation functions of the test FMUs, written from the
 * FMI 3.0 specification (sections 2.2 and 4.2). Value references: Float64
 * 0..NF-1 (each of kSize[vr] elements), Int32 100.., Boolean 200..,
 * String 300... A model file defines, before including this file:
 *   MODEL_TOKEN, NF, NFV (all Float64 elements), NI, NB, NS,
 *   static const size_t kSize[NF];
 *   static void ModelDefaults(Model* m); static void ModelOutputs(Model* m);
 *   static fmi3Status ModelStep(Instance* c, double t, double h, bool* early, double* last,
 *                               bool* terminate);
 * and may define MODEL_HAS_EXTRA_TYPES (it defines fmi3Get/Set of Float32
 * and the integer types beyond Int32 itself) and MODEL_HAS_BINARY (the same
 * for Binary); otherwise this file defines them for a model with no
 * variable of those types. Every function FMI 3.0.2 requires of a
 * co-simulation binary is present (section 2.5: all common functions and
 * the interface type's, even for capabilities the FMU lacks). */
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
  /* FMI 3.0.2 Step Mode: no fmi3Get* may follow an fmi3Set* without an
   * fmi3DoStep in between; this FMU refuses one (fmi3Error), as a
   * conforming FMU may. */
  bool step_mode;
  bool set_since_step;
} Instance;

/* For the accessors: a get after a set in step mode is refused. */
#define FMI3_CHECK_GET(function)                                                       \
  if (((Instance*)c)->step_mode && ((Instance*)c)->set_since_step) {                   \
    Instance* ci_ = (Instance*)c;                                                      \
    if (ci_->log)                                                                      \
      ci_->log(ci_->env, fmi3Error, "logStatusError",                                  \
               function " after fmi3Set* without fmi3DoStep in between (FMI 3.0.2, Step Mode)"); \
    return fmi3Error;                                                                  \
  }
#define FMI3_NOTE_SET() ((Instance*)c)->set_since_step = ((Instance*)c)->step_mode;

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
EXPORT fmi3Status fmi3ExitInitializationMode(fmi3Instance c) {
  ((Instance*)c)->step_mode = true;
  return fmi3OK;
}
EXPORT fmi3Status fmi3Terminate(fmi3Instance c) {
  /* Logged, so that tests see which call sequences an importer made. */
  Instance* ci = (Instance*)c;
  if (ci->log) ci->log(ci->env, fmi3OK, "logEvents", "fmi3Terminate called");
  return fmi3OK;
}

EXPORT fmi3Status fmi3GetFloat64(fmi3Instance c, const fmi3ValueReference vr[], size_t n,
                                 fmi3Float64 v[], size_t nv) {
  Model* m = &((Instance*)c)->m;
  FMI3_CHECK_GET("fmi3GetFloat64")
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
  FMI3_NOTE_SET()
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
  FMI3_CHECK_GET("fmi3GetInt32")
  CHECK3(100, NI)
  ModelOutputs(m);
  for (size_t k = 0; k < n; ++k) v[k] = m->i[vr[k] - 100];
  return fmi3OK;
}
EXPORT fmi3Status fmi3SetInt32(fmi3Instance c, const fmi3ValueReference vr[], size_t n, const fmi3Int32 v[], size_t nv) {
  Model* m = &((Instance*)c)->m;
  FMI3_NOTE_SET()
  CHECK3(100, NI)
  for (size_t k = 0; k < n; ++k) m->i[vr[k] - 100] = v[k];
  return fmi3OK;
}
EXPORT fmi3Status fmi3GetBoolean(fmi3Instance c, const fmi3ValueReference vr[], size_t n, fmi3Boolean v[], size_t nv) {
  Model* m = &((Instance*)c)->m;
  FMI3_CHECK_GET("fmi3GetBoolean")
  CHECK3(200, NB)
  ModelOutputs(m);
  for (size_t k = 0; k < n; ++k) v[k] = m->b[vr[k] - 200];
  return fmi3OK;
}
EXPORT fmi3Status fmi3SetBoolean(fmi3Instance c, const fmi3ValueReference vr[], size_t n, const fmi3Boolean v[], size_t nv) {
  Model* m = &((Instance*)c)->m;
  FMI3_NOTE_SET()
  CHECK3(200, NB)
  for (size_t k = 0; k < n; ++k) m->b[vr[k] - 200] = v[k];
  return fmi3OK;
}
EXPORT fmi3Status fmi3GetString(fmi3Instance c, const fmi3ValueReference vr[], size_t n, fmi3String v[], size_t nv) {
  Model* m = &((Instance*)c)->m;
  FMI3_CHECK_GET("fmi3GetString")
  CHECK3(300, NS)
  ModelOutputs(m);
  for (size_t k = 0; k < n; ++k) v[k] = m->s[vr[k] - 300];
  return fmi3OK;
}
EXPORT fmi3Status fmi3SetString(fmi3Instance c, const fmi3ValueReference vr[], size_t n, const fmi3String v[], size_t nv) {
  Model* m = &((Instance*)c)->m;
  FMI3_NOTE_SET()
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
  ci->set_since_step = false;
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

/* The functions of capabilities these FMUs lack, present as FMI 3.0.2
 * section 2.5 requires, refusing (fmi3Error, logged). */
static fmi3Status Refuse(fmi3Instance c, const char* function) {
  Instance* ci = (Instance*)c;
  if (ci && ci->log) ci->log(ci->env, fmi3Error, "logStatusError", function);
  return fmi3Error;
}
/* Accessors of a type the model has no variable of: nothing to get or set. */
#define NO_VARIABLES(Name, T)                                                                 \
  EXPORT fmi3Status fmi3Get##Name(fmi3Instance c, const fmi3ValueReference vr[], size_t n,   \
                                  T v[], size_t nv) {                                         \
    (void)vr; (void)v; (void)nv;                                                              \
    return n == 0 ? fmi3OK : Refuse(c, "fmi3Get" #Name ": the FMU has no such variable");    \
  }                                                                                           \
  EXPORT fmi3Status fmi3Set##Name(fmi3Instance c, const fmi3ValueReference vr[], size_t n,   \
                                  const T v[], size_t nv) {                                   \
    (void)vr; (void)v; (void)nv;                                                              \
    return n == 0 ? fmi3OK : Refuse(c, "fmi3Set" #Name ": the FMU has no such variable");    \
  }
#ifndef MODEL_HAS_EXTRA_TYPES
NO_VARIABLES(Float32, float)
NO_VARIABLES(Int8, int8_t)
NO_VARIABLES(UInt8, uint8_t)
NO_VARIABLES(Int16, int16_t)
NO_VARIABLES(UInt16, uint16_t)
NO_VARIABLES(UInt32, uint32_t)
NO_VARIABLES(Int64, int64_t)
NO_VARIABLES(UInt64, uint64_t)
#endif
#undef NO_VARIABLES
EXPORT fmi3Status fmi3GetClock(fmi3Instance c, const fmi3ValueReference vr[], size_t n, bool v[]) {
  (void)vr; (void)v;
  return n == 0 ? fmi3OK : Refuse(c, "fmi3GetClock: the FMU has no clocks");
}
EXPORT fmi3Status fmi3SetClock(fmi3Instance c, const fmi3ValueReference vr[], size_t n,
                               const bool v[]) {
  (void)vr; (void)v;
  return n == 0 ? fmi3OK : Refuse(c, "fmi3SetClock: the FMU has no clocks");
}
#ifndef MODEL_HAS_BINARY
EXPORT fmi3Status fmi3GetBinary(fmi3Instance c, const fmi3ValueReference vr[], size_t n,
                                size_t sizes[], const fmi3Byte* v[], size_t nv) {
  (void)vr; (void)sizes; (void)v; (void)nv;
  return n == 0 ? fmi3OK : Refuse(c, "fmi3GetBinary: the FMU has no Binary variable");
}
EXPORT fmi3Status fmi3SetBinary(fmi3Instance c, const fmi3ValueReference vr[], size_t n,
                                const size_t sizes[], const fmi3Byte* const v[], size_t nv) {
  (void)vr; (void)sizes; (void)v; (void)nv;
  return n == 0 ? fmi3OK : Refuse(c, "fmi3SetBinary: the FMU has no Binary variable");
}
#endif
EXPORT fmi3Status fmi3SetDebugLogging(fmi3Instance c, bool on, size_t n, const fmi3String cat[]) {
  (void)c; (void)on; (void)n; (void)cat;
  return fmi3OK;
}
EXPORT fmi3Status fmi3EnterEventMode(fmi3Instance c) {
  return Refuse(c, "fmi3EnterEventMode: no event mode");
}
EXPORT fmi3Status fmi3Reset(fmi3Instance c) {
  Instance* ci = (Instance*)c;
  ModelDefaults(&ci->m);
  ci->step_mode = false;
  ci->set_since_step = false;
  return fmi3OK;
}
EXPORT fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance c, fmi3ValueReference vr,
                                                      size_t* n) {
  (void)vr; (void)n;
  return Refuse(c, "fmi3GetNumberOfVariableDependencies: see ModelStructure");
}
EXPORT fmi3Status fmi3GetVariableDependencies(fmi3Instance c, fmi3ValueReference vr,
                                              size_t element[], fmi3ValueReference independent[],
                                              size_t element_independent[], int kind[],
                                              size_t n) {
  (void)vr; (void)element; (void)independent; (void)element_independent; (void)kind; (void)n;
  return Refuse(c, "fmi3GetVariableDependencies: see ModelStructure");
}
EXPORT fmi3Status fmi3GetDirectionalDerivative(fmi3Instance c, const fmi3ValueReference u[],
                                               size_t nu, const fmi3ValueReference k[], size_t nk,
                                               const double seed[], size_t ns, double sens[],
                                               size_t nsens) {
  (void)u; (void)nu; (void)k; (void)nk; (void)seed; (void)ns; (void)sens; (void)nsens;
  return Refuse(c, "fmi3GetDirectionalDerivative: not provided");
}
EXPORT fmi3Status fmi3GetAdjointDerivative(fmi3Instance c, const fmi3ValueReference u[],
                                           size_t nu, const fmi3ValueReference k[], size_t nk,
                                           const double seed[], size_t ns, double sens[],
                                           size_t nsens) {
  (void)u; (void)nu; (void)k; (void)nk; (void)seed; (void)ns; (void)sens; (void)nsens;
  return Refuse(c, "fmi3GetAdjointDerivative: not provided");
}
EXPORT fmi3Status fmi3EnterConfigurationMode(fmi3Instance c) {
  return Refuse(c, "fmi3EnterConfigurationMode: no tunable structural parameter");
}
EXPORT fmi3Status fmi3ExitConfigurationMode(fmi3Instance c) {
  return Refuse(c, "fmi3ExitConfigurationMode: no configuration mode");
}
EXPORT fmi3Status fmi3GetIntervalDecimal(fmi3Instance c, const fmi3ValueReference vr[], size_t n,
                                         double interval[], int qualifier[]) {
  (void)vr; (void)n; (void)interval; (void)qualifier;
  return Refuse(c, "fmi3GetIntervalDecimal: no clocks");
}
EXPORT fmi3Status fmi3GetIntervalFraction(fmi3Instance c, const fmi3ValueReference vr[], size_t n,
                                          uint64_t counter[], uint64_t resolution[],
                                          int qualifier[]) {
  (void)vr; (void)n; (void)counter; (void)resolution; (void)qualifier;
  return Refuse(c, "fmi3GetIntervalFraction: no clocks");
}
EXPORT fmi3Status fmi3GetShiftDecimal(fmi3Instance c, const fmi3ValueReference vr[], size_t n,
                                      double shift[]) {
  (void)vr; (void)n; (void)shift;
  return Refuse(c, "fmi3GetShiftDecimal: no clocks");
}
EXPORT fmi3Status fmi3GetShiftFraction(fmi3Instance c, const fmi3ValueReference vr[], size_t n,
                                       uint64_t counter[], uint64_t resolution[]) {
  (void)vr; (void)n; (void)counter; (void)resolution;
  return Refuse(c, "fmi3GetShiftFraction: no clocks");
}
EXPORT fmi3Status fmi3SetIntervalDecimal(fmi3Instance c, const fmi3ValueReference vr[], size_t n,
                                         const double interval[]) {
  (void)vr; (void)n; (void)interval;
  return Refuse(c, "fmi3SetIntervalDecimal: no clocks");
}
EXPORT fmi3Status fmi3SetIntervalFraction(fmi3Instance c, const fmi3ValueReference vr[], size_t n,
                                          const uint64_t counter[], const uint64_t resolution[]) {
  (void)vr; (void)n; (void)counter; (void)resolution;
  return Refuse(c, "fmi3SetIntervalFraction: no clocks");
}
EXPORT fmi3Status fmi3SetShiftDecimal(fmi3Instance c, const fmi3ValueReference vr[], size_t n,
                                      const double shift[]) {
  (void)vr; (void)n; (void)shift;
  return Refuse(c, "fmi3SetShiftDecimal: no clocks");
}
EXPORT fmi3Status fmi3SetShiftFraction(fmi3Instance c, const fmi3ValueReference vr[], size_t n,
                                       const uint64_t counter[], const uint64_t resolution[]) {
  (void)vr; (void)n; (void)counter; (void)resolution;
  return Refuse(c, "fmi3SetShiftFraction: no clocks");
}
EXPORT fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance c) {
  return Refuse(c, "fmi3EvaluateDiscreteStates: no event mode");
}
EXPORT fmi3Status fmi3UpdateDiscreteStates(fmi3Instance c, bool* a, bool* b, bool* d, bool* e,
                                           bool* f, double* g) {
  (void)a; (void)b; (void)d; (void)e; (void)f; (void)g;
  return Refuse(c, "fmi3UpdateDiscreteStates: no event mode");
}
EXPORT fmi3Status fmi3EnterStepMode(fmi3Instance c) {
  return Refuse(c, "fmi3EnterStepMode: no event mode (step mode follows initialization)");
}
EXPORT fmi3Status fmi3GetOutputDerivatives(fmi3Instance c, const fmi3ValueReference vr[], size_t n,
                                           const int32_t order[], double v[], size_t nv) {
  (void)vr; (void)n; (void)order; (void)v; (void)nv;
  return Refuse(c, "fmi3GetOutputDerivatives: maxOutputDerivativeOrder is 0");
}
