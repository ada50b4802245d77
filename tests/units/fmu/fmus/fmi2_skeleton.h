/* The FMI 2.0 co-simulation functions of the test FMUs, written from the
 * FMI 2.0.4 specification (sections 2.1 and 4.2). A model file defines,
 * before including this file:
 *   NR, NI, NB, NS   counts of Real, Integer, Boolean, String variables
 *                    (value references 0..N-1 of each type)
 *   static void ModelDefaults(Model* m);            start values
 *   static void ModelOutputs(Model* m);             outputs from inputs
 *   static fmi2Status ModelStep(Instance* c, double t, double h);
 *   MODEL_CAN_GET_SET_STATE (0 or 1)
 * Every Get first computes the outputs (direct feedthrough). */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

typedef void* fmi2Component;
typedef void* fmi2ComponentEnvironment;
typedef void* fmi2FMUstate;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Integer;
typedef int fmi2Boolean;
typedef char fmi2Char;
typedef const fmi2Char* fmi2String;
typedef char fmi2Byte;
typedef enum { fmi2OK, fmi2Warning, fmi2Discard, fmi2Error, fmi2Fatal, fmi2Pending } fmi2Status;
typedef enum { fmi2ModelExchange, fmi2CoSimulation } fmi2Type;
typedef enum {
  fmi2DoStepStatus,
  fmi2PendingStatus,
  fmi2LastSuccessfulTime,
  fmi2Terminated
} fmi2StatusKind;
typedef void (*fmi2CallbackLogger)(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String,
                                   fmi2String, ...);
typedef struct {
  fmi2CallbackLogger logger;
  void* (*allocateMemory)(size_t, size_t);
  void (*freeMemory)(void*);
  void (*stepFinished)(fmi2ComponentEnvironment, fmi2Status);
  fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;

#define EXPORT __attribute__((visibility("default")))
#define STR_LEN 64

typedef struct {
  double r[NR > 0 ? NR : 1];
  int i[NI > 0 ? NI : 1];
  int b[NB > 0 ? NB : 1];
  char s[NS > 0 ? NS : 1][STR_LEN];
  double time;
  double last_successful_time;
  int terminated; /* fmi2GetBooleanStatus(fmi2Terminated) */
  int started; /* set by the first doStep */
} Model;

typedef struct {
  Model m;
  fmi2CallbackFunctions cb;
  char name[STR_LEN];
  /* FMI 2.0.4 section 4.2.4: after fmi2ExitInitializationMode no fmi2Get*
   * may follow an fmi2Set* without an fmi2DoStep in between; this FMU
   * refuses one (fmi2Error), as a conforming FMU may. */
  int step_mode;
  int set_since_step;
} Instance;

static void ModelDefaults(Model* m);
static void ModelOutputs(Model* m);
static fmi2Status ModelStep(Instance* c, double t, double h);

static void Say(Instance* c, fmi2Status status, const char* category, const char* format, ...) {
  char text[256];
  va_list args;
  va_start(args, format);
  vsnprintf(text, sizeof text, format, args);
  va_end(args);
  if (c->cb.logger) c->cb.logger(c->cb.componentEnvironment, c->name, status, category, "%s", text);
}

EXPORT const char* fmi2GetTypesPlatform(void) { return "default"; }
EXPORT const char* fmi2GetVersion(void) { return "2.0"; }

EXPORT fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid,
                                     fmi2String resources, const fmi2CallbackFunctions* cb,
                                     fmi2Boolean visible, fmi2Boolean logging) {
  (void)visible;
  (void)logging;
  (void)resources;
  if (type != fmi2CoSimulation || !cb) return NULL;
  if (strcmp(guid, MODEL_GUID) != 0) {
    if (cb->logger) cb->logger(cb->componentEnvironment, name, fmi2Error, "error", "wrong guid %s", guid);
    return NULL;
  }
  Instance* c = (Instance*)calloc(1, sizeof(Instance));
  c->cb = *cb;
  strncpy(c->name, name, STR_LEN - 1);
  ModelDefaults(&c->m);
  Say(c, fmi2OK, "logAll", "instantiated %s", MODEL_GUID);
  return c;
}

EXPORT void fmi2FreeInstance(fmi2Component c) { free(c); }
EXPORT fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n, const fmi2String cat[]) {
  (void)c; (void)on; (void)n; (void)cat;
  return fmi2OK;
}
EXPORT fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean tol_defined, fmi2Real tol,
                                      fmi2Real start, fmi2Boolean stop_defined, fmi2Real stop) {
  (void)tol_defined; (void)tol; (void)stop_defined; (void)stop;
  ((Instance*)c)->m.time = start;
  return fmi2OK;
}
EXPORT fmi2Status fmi2EnterInitializationMode(fmi2Component c) { (void)c; return fmi2OK; }
EXPORT fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
  ((Instance*)c)->step_mode = 1;
  return fmi2OK;
}
EXPORT fmi2Status fmi2Terminate(fmi2Component c) {
  /* Logged, so that tests see which call sequences an importer made. */
  Say((Instance*)c, fmi2OK, "logAll", "fmi2Terminate called");
  return fmi2OK;
}
EXPORT fmi2Status fmi2Reset(fmi2Component c) {
  ModelDefaults(&((Instance*)c)->m);
  ((Instance*)c)->step_mode = 0;
  ((Instance*)c)->set_since_step = 0;
  return fmi2OK;
}

#define CHECK_VR(count)                                        \
  for (size_t k = 0; k < n; ++k)                               \
    if ((long)vr[k] >= (long)(count)) return fmi2Error;
/* A get after a set in step mode, refused (see Instance). */
#define CHECK_GET(function)                                                              \
  if (((Instance*)c)->step_mode && ((Instance*)c)->set_since_step) {                     \
    Say((Instance*)c, fmi2Error, "logStatusError",                                       \
        function " after fmi2Set* without fmi2DoStep in between (FMI 2.0.4, 4.2.4)");     \
    return fmi2Error;                                                                    \
  }
#define NOTE_SET() ((Instance*)c)->set_since_step = ((Instance*)c)->step_mode;

EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real v[]) {
  Model* m = &((Instance*)c)->m;
  CHECK_GET("fmi2GetReal")
  CHECK_VR(NR)
  ModelOutputs(m);
  for (size_t k = 0; k < n; ++k) v[k] = m->r[vr[k]];
  return fmi2OK;
}
EXPORT fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer v[]) {
  Model* m = &((Instance*)c)->m;
  CHECK_GET("fmi2GetInteger")
  CHECK_VR(NI)
  ModelOutputs(m);
  for (size_t k = 0; k < n; ++k) v[k] = m->i[vr[k]];
  return fmi2OK;
}
EXPORT fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean v[]) {
  Model* m = &((Instance*)c)->m;
  CHECK_GET("fmi2GetBoolean")
  CHECK_VR(NB)
  ModelOutputs(m);
  for (size_t k = 0; k < n; ++k) v[k] = m->b[vr[k]];
  return fmi2OK;
}
EXPORT fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String v[]) {
  Model* m = &((Instance*)c)->m;
  CHECK_GET("fmi2GetString")
  CHECK_VR(NS)
  ModelOutputs(m);
  for (size_t k = 0; k < n; ++k) v[k] = m->s[vr[k]];
  return fmi2OK;
}
EXPORT fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real v[]) {
  Model* m = &((Instance*)c)->m;
  CHECK_VR(NR)
  NOTE_SET()
  for (size_t k = 0; k < n; ++k) m->r[vr[k]] = v[k];
  return fmi2OK;
}
EXPORT fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer v[]) {
  Model* m = &((Instance*)c)->m;
  CHECK_VR(NI)
  NOTE_SET()
  for (size_t k = 0; k < n; ++k) m->i[vr[k]] = v[k];
  return fmi2OK;
}
EXPORT fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean v[]) {
  Model* m = &((Instance*)c)->m;
  CHECK_VR(NB)
  NOTE_SET()
  for (size_t k = 0; k < n; ++k) m->b[vr[k]] = v[k] != 0;
  return fmi2OK;
}
EXPORT fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String v[]) {
  Model* m = &((Instance*)c)->m;
  CHECK_VR(NS)
  NOTE_SET()
  for (size_t k = 0; k < n; ++k) {
    strncpy(m->s[vr[k]], v[k] ? v[k] : "", STR_LEN - 1);
    m->s[vr[k]][STR_LEN - 1] = 0;
  }
  return fmi2OK;
}

EXPORT fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean no_set_prior) {
  (void)no_set_prior;
  Instance* ci = (Instance*)c;
  ci->set_since_step = 0;
  ModelOutputs(&ci->m);
  ci->m.started = 1;
  return ModelStep(ci, t, h);
}
EXPORT fmi2Status fmi2CancelStep(fmi2Component c) { (void)c; return fmi2Error; }
EXPORT fmi2Status fmi2GetRealStatus(fmi2Component c, fmi2StatusKind s, fmi2Real* v) {
  if (s != fmi2LastSuccessfulTime) return fmi2Discard;
  *v = ((Instance*)c)->m.last_successful_time;
  return fmi2OK;
}

EXPORT fmi2Status fmi2GetBooleanStatus(fmi2Component c, fmi2StatusKind s, fmi2Boolean* v) {
  if (s != fmi2Terminated) return fmi2Discard;
  *v = ((Instance*)c)->m.terminated;
  return fmi2OK;
}

/* The rest of the functions FMI 2.0.4 requires of every co-simulation
 * binary (sections 2.1 and 4.2), for capabilities these FMUs do not have:
 * present, refusing. Status kinds they cannot report give fmi2Discard
 * (section 4.2.3). */
EXPORT fmi2Status fmi2GetStatus(fmi2Component c, fmi2StatusKind s, fmi2Status* v) {
  (void)c; (void)s; (void)v;
  return fmi2Discard;
}
EXPORT fmi2Status fmi2GetIntegerStatus(fmi2Component c, fmi2StatusKind s, fmi2Integer* v) {
  (void)c; (void)s; (void)v;
  return fmi2Discard;
}
EXPORT fmi2Status fmi2GetStringStatus(fmi2Component c, fmi2StatusKind s, fmi2String* v) {
  (void)c; (void)s; (void)v;
  return fmi2Discard;
}
EXPORT fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[],
                                               size_t nu, const fmi2ValueReference z[], size_t nz,
                                               const fmi2Real dv[], fmi2Real dz[]) {
  (void)u; (void)nu; (void)z; (void)nz; (void)dv; (void)dz;
  Say((Instance*)c, fmi2Error, "logStatusError", "no directional derivatives");
  return fmi2Error;
}
EXPORT fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
                                              size_t n, const fmi2Integer order[],
                                              const fmi2Real v[]) {
  (void)vr; (void)n; (void)order; (void)v;
  Say((Instance*)c, fmi2Error, "logStatusError", "no input derivatives (canInterpolateInputs)");
  return fmi2Error;
}
EXPORT fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
                                               size_t n, const fmi2Integer order[], fmi2Real v[]) {
  (void)vr; (void)n; (void)order; (void)v;
  Say((Instance*)c, fmi2Error, "logStatusError", "no output derivatives (maxOutputDerivativeOrder 0)");
  return fmi2Error;
}

#if !MODEL_CAN_GET_SET_STATE
/* Present, refusing: canGetAndSetFMUstate is false. */
static fmi2Status NoState(fmi2Component c, const char* function) {
  Say((Instance*)c, fmi2Error, "logStatusError", "%s: no FMU state", function);
  return fmi2Error;
}
EXPORT fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate* s) {
  (void)s;
  return NoState(c, "fmi2GetFMUstate");
}
EXPORT fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s) {
  (void)s;
  return NoState(c, "fmi2SetFMUstate");
}
EXPORT fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate* s) {
  (void)s;
  return NoState(c, "fmi2FreeFMUstate");
}
EXPORT fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate s, size_t* size) {
  (void)s; (void)size;
  return NoState(c, "fmi2SerializedFMUstateSize");
}
EXPORT fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate s, fmi2Byte b[], size_t size) {
  (void)s; (void)b; (void)size;
  return NoState(c, "fmi2SerializeFMUstate");
}
EXPORT fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte b[], size_t size,
                                          fmi2FMUstate* s) {
  (void)s; (void)b; (void)size;
  return NoState(c, "fmi2DeSerializeFMUstate");
}
#else
EXPORT fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate* s) {
  Model* copy = (Model*)malloc(sizeof(Model));
  *copy = ((Instance*)c)->m;
  *s = copy;
  return fmi2OK;
}
EXPORT fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s) {
  ((Instance*)c)->m = *(Model*)s;
  return fmi2OK;
}
EXPORT fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate* s) {
  (void)c;
  free(*s);
  *s = NULL;
  return fmi2OK;
}
EXPORT fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate s, size_t* size) {
  (void)c; (void)s;
  *size = sizeof(Model);
  return fmi2OK;
}
EXPORT fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate s, fmi2Byte b[], size_t size) {
  (void)c;
  if (size != sizeof(Model)) return fmi2Error;
  memcpy(b, s, sizeof(Model));
  return fmi2OK;
}
EXPORT fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte b[], size_t size, fmi2FMUstate* s) {
  (void)c;
  if (size != sizeof(Model)) return fmi2Error;
  Model* copy = (Model*)malloc(sizeof(Model));
  memcpy(copy, b, sizeof(Model));
  *s = copy;
  return fmi2OK;
}
#endif
