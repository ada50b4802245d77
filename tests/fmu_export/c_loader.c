/* A standalone FMI 2.0 co-simulation master in C, to show that an FMU
 * written by `linesim export-fmu` loads outside linesim: it unzips the FMU,
 * reads the guid, model identifier and value references from
 * modelDescription.xml (plain string search), dlopens
 * binaries/linux64/<modelIdentifier>.so and calls fmi2Instantiate,
 * fmi2SetupExperiment, fmi2EnterInitializationMode, fmi2SetReal,
 * fmi2ExitInitializationMode, fmi2DoStep, fmi2GetReal, fmi2Terminate and
 * fmi2FreeInstance. The types and signatures are those of "Functional
 * Mock-up Interface for Model Exchange and Co-Simulation" 2.0.4, sections
 * 2.1 and 4.2, declared here so that this file needs no linesim header.
 *
 * usage: c_loader FMU FOLDER   (a dc_motor FMU with the maxon RE 40 148877
 * parameters). It runs 24 V for 0.2 s and checks the no-load speed against
 * k_t V / (R b + k_t^2) from the maxon data sheet (k_t = 30.2 mNm/A,
 * R = 0.299 Ohm, b = 5.2123e-6 N.m.s/rad derived from the no-load point).
 * Exit status 0 and a line "ok: ..." on success. */
#include <dlfcn.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <zip.h>

typedef void* fmi2Component;
typedef void* fmi2ComponentEnvironment;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Boolean;
typedef const char* fmi2String;
typedef enum { fmi2OK, fmi2Warning, fmi2Discard, fmi2Error, fmi2Fatal, fmi2Pending } fmi2Status;
typedef enum { fmi2ModelExchange, fmi2CoSimulation } fmi2Type;
typedef struct {
  void (*logger)(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String, fmi2String, ...);
  void* (*allocateMemory)(size_t, size_t);
  void (*freeMemory)(void*);
  void (*stepFinished)(fmi2ComponentEnvironment, fmi2Status);
  fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;

typedef fmi2Component (*InstantiateFn)(fmi2String, fmi2Type, fmi2String, fmi2String,
                                       const fmi2CallbackFunctions*, fmi2Boolean, fmi2Boolean);
typedef fmi2Status (*SetupExperimentFn)(fmi2Component, fmi2Boolean, fmi2Real, fmi2Real,
                                        fmi2Boolean, fmi2Real);
typedef fmi2Status (*ComponentFn)(fmi2Component);
typedef void (*FreeInstanceFn)(fmi2Component);
typedef fmi2Status (*SetRealFn)(fmi2Component, const fmi2ValueReference[], size_t,
                                const fmi2Real[]);
typedef fmi2Status (*GetRealFn)(fmi2Component, const fmi2ValueReference[], size_t, fmi2Real[]);
typedef fmi2Status (*DoStepFn)(fmi2Component, fmi2Real, fmi2Real, fmi2Boolean);

static void Logger(fmi2ComponentEnvironment env, fmi2String instance, fmi2Status status,
                   fmi2String category, fmi2String message, ...) {
  va_list args;
  (void)env;
  fprintf(stderr, "[%s] status %d %s: ", instance, (int)status, category);
  va_start(args, message);
  vfprintf(stderr, message, args);
  va_end(args);
  fprintf(stderr, "\n");
}

static int Fail(const char* what) {
  fprintf(stderr, "c_loader: %s\n", what);
  return 1;
}

/* mkdir -p of the folders of `path` (its last component is a file). */
static void MakeParents(char* path) {
  for (char* p = path + 1; *p; ++p) {
    if (*p == '/') {
      *p = '\0';
      mkdir(path, 0700);
      *p = '/';
    }
  }
}

static int Unzip(const char* fmu, const char* folder) {
  int error = 0;
  zip_t* zip = zip_open(fmu, ZIP_RDONLY, &error);
  if (!zip) return Fail("cannot open the FMU");
  mkdir(folder, 0700);
  zip_int64_t n = zip_get_num_entries(zip, 0);
  for (zip_int64_t i = 0; i < n; ++i) {
    const char* name = zip_get_name(zip, (zip_uint64_t)i, 0);
    if (!name || strstr(name, "..") || name[0] == '/') return Fail("unsafe entry in the FMU");
    size_t len = strlen(name);
    if (len == 0 || name[len - 1] == '/') continue;
    char* path = malloc(strlen(folder) + len + 2);
    sprintf(path, "%s/%s", folder, name);
    MakeParents(path);
    zip_file_t* in = zip_fopen_index(zip, (zip_uint64_t)i, 0);
    FILE* out = fopen(path, "wb");
    if (!in || !out) return Fail("cannot unpack an entry");
    char buffer[65536];
    zip_int64_t got;
    while ((got = zip_fread(in, buffer, sizeof buffer)) > 0) fwrite(buffer, 1, (size_t)got, out);
    fclose(out);
    zip_fclose(in);
    free(path);
  }
  zip_close(zip);
  return 0;
}

static char* ReadAll(const char* file) {
  FILE* f = fopen(file, "rb");
  if (!f) return NULL;
  fseek(f, 0, SEEK_END);
  long size = ftell(f);
  fseek(f, 0, SEEK_SET);
  char* text = malloc((size_t)size + 1);
  size_t got = fread(text, 1, (size_t)size, f);
  text[got] = '\0';
  fclose(f);
  return text;
}

/* The value of attribute `attr` after the first occurrence of `after`. */
static int Attribute(const char* xml, const char* after, const char* attr, char* out, size_t n) {
  const char* p = strstr(xml, after);
  if (!p) return 0;
  p = strstr(p, attr);
  if (!p) return 0;
  p += strlen(attr);
  const char* end = strchr(p, '"');
  if (!end || (size_t)(end - p) >= n) return 0;
  memcpy(out, p, (size_t)(end - p));
  out[end - p] = '\0';
  return 1;
}

static int ValueReference(const char* xml, const char* name, fmi2ValueReference* vr) {
  char key[128], value[32];
  snprintf(key, sizeof key, "name=\"%s\"", name);
  if (!Attribute(xml, key, "valueReference=\"", value, sizeof value)) return 0;
  *vr = (fmi2ValueReference)strtoul(value, NULL, 10);
  return 1;
}

int main(int argc, char** argv) {
  if (argc != 3) return Fail("usage: c_loader FMU FOLDER");
  const char* folder = argv[2];
  if (Unzip(argv[1], folder) != 0) return 1;

  char file[4096];
  snprintf(file, sizeof file, "%s/modelDescription.xml", folder);
  char* xml = ReadAll(file);
  if (!xml) return Fail("no modelDescription.xml");
  char guid[128], identifier[128];
  if (!Attribute(xml, "<fmiModelDescription", "guid=\"", guid, sizeof guid) ||
      !Attribute(xml, "<CoSimulation", "modelIdentifier=\"", identifier, sizeof identifier)) {
    return Fail("no guid or modelIdentifier");
  }
  fmi2ValueReference vr_voltage, vr_speed, vr_current;
  if (!ValueReference(xml, "voltage", &vr_voltage) || !ValueReference(xml, "speed", &vr_speed) ||
      !ValueReference(xml, "current", &vr_current)) {
    return Fail("no voltage, speed or current variable");
  }

  snprintf(file, sizeof file, "%s/binaries/linux64/%s.so", folder, identifier);
  void* so = dlopen(file, RTLD_NOW | RTLD_LOCAL);
  if (!so) return Fail(dlerror());
  InstantiateFn instantiate = (InstantiateFn)dlsym(so, "fmi2Instantiate");
  SetupExperimentFn setup = (SetupExperimentFn)dlsym(so, "fmi2SetupExperiment");
  ComponentFn enter = (ComponentFn)dlsym(so, "fmi2EnterInitializationMode");
  ComponentFn exit_init = (ComponentFn)dlsym(so, "fmi2ExitInitializationMode");
  ComponentFn terminate = (ComponentFn)dlsym(so, "fmi2Terminate");
  FreeInstanceFn free_instance = (FreeInstanceFn)dlsym(so, "fmi2FreeInstance");
  SetRealFn set_real = (SetRealFn)dlsym(so, "fmi2SetReal");
  GetRealFn get_real = (GetRealFn)dlsym(so, "fmi2GetReal");
  DoStepFn do_step = (DoStepFn)dlsym(so, "fmi2DoStep");
  if (!instantiate || !setup || !enter || !exit_init || !terminate || !free_instance ||
      !set_real || !get_real || !do_step) {
    return Fail("a function of the FMI 2.0 API is missing");
  }

  char resources[4200];
  snprintf(resources, sizeof resources, "file://%s/resources", folder);
  fmi2CallbackFunctions callbacks = {Logger, calloc, free, NULL, NULL};
  fmi2Component c = instantiate("motor", fmi2CoSimulation, guid, resources, &callbacks, 0, 0);
  if (!c) return Fail("fmi2Instantiate failed");
  const fmi2Real volts = 24.0;
  if (setup(c, 0, 0.0, 0.0, 0, 0.0) != fmi2OK || enter(c) != fmi2OK ||
      set_real(c, &vr_voltage, 1, &volts) != fmi2OK || exit_init(c) != fmi2OK) {
    return Fail("initialization failed");
  }
  const double h = 0.001;
  fmi2Real speed = 0, current = 0;
  for (int k = 0; k < 200; ++k) {
    if (do_step(c, k * h, h, 1) != fmi2OK) return Fail("fmi2DoStep failed");
    if (get_real(c, &vr_speed, 1, &speed) != fmi2OK ||
        get_real(c, &vr_current, 1, &current) != fmi2OK) {
      return Fail("fmi2GetReal failed");
    }
  }
  terminate(c);
  free_instance(c);
  dlclose(so);
  free(xml);

  const double kt = 0.0302, r = 0.299, b = 5.2123e-6;
  const double no_load = kt * volts / (r * b + kt * kt);
  /* The slow time constant R J / (k_t^2 + R b) with J = 1.42e-5 kg.m2 is
   * 4.6 ms: after 0.2 s nothing of the start is left; CVODE's tolerances
   * (1e-8 relative) bound the rest. */
  if (fabs(speed - no_load) > 1e-6 * no_load) {
    fprintf(stderr, "c_loader: speed %.9g rad/s, expected %.9g\n", speed, no_load);
    return 1;
  }
  printf("ok: speed %.9g rad/s (expected %.9g), current %.6g A\n", speed, no_load, current);
  return 0;
}
