/* Every FMI 3.0 scalar type (fmus/types3.xml): each <type>_out is its
 * <type>_in, f32_out is f32_in; y[k] = (k + 1) * f32_in, an array of n
 * elements where n is a UInt64 structural parameter (start 3). A Binary
 * output (vr 491) is its Binary input (vr 490): linesim leaves both out,
 * as the Reference-FMUs' Feedthrough's, whose model structure lists the
 * Binary output. */
#define MODEL_TOKEN "{linesim-test-types-3}"
#define NF 1
#define NFV 3
#define NI 0
#define NB 0
#define NS 0
#include <stddef.h>
#include <stdint.h>
static const size_t kSize[NF] = {3};
#define MODEL_HAS_EXTRA_TYPES
#define MODEL_HAS_BINARY
#define BLOB_MAX 64
#define MODEL_EXTRA_FIELDS \
  uint8_t blob[2][BLOB_MAX]; \
  size_t blob_size[2];     \
  float f32[2];            \
  int8_t i8[2];            \
  uint8_t u8[2];           \
  int16_t i16[2];          \
  uint16_t u16[2];         \
  uint32_t u32[2];         \
  int64_t i64[2];          \
  uint64_t u64[2];         \
  int64_t e[2];
#include "fmi3_skeleton.h"

static void ModelDefaults(Model* m) {
  memset(m, 0, sizeof *m);
  m->e[0] = m->e[1] = 1;
  memcpy(m->blob[0], "foo", 3); /* start 666f6f */
  m->blob_size[0] = 3;
}

static void ModelOutputs(Model* m) {
  m->f32[1] = m->f32[0];
  m->i8[1] = m->i8[0];
  m->u8[1] = m->u8[0];
  m->i16[1] = m->i16[0];
  m->u16[1] = m->u16[0];
  m->u32[1] = m->u32[0];
  m->i64[1] = m->i64[0];
  m->u64[1] = m->u64[0];
  m->e[1] = m->e[0];
  memcpy(m->blob[1], m->blob[0], m->blob_size[0]);
  m->blob_size[1] = m->blob_size[0];
  for (int k = 0; k < 3; ++k) m->f[k] = (k + 1) * (double)m->f32[0];
}

static fmi3Status ModelStep(Instance* c, double t, double h, bool* early, double* last,
                            bool* terminate) {
  (void)early; (void)last; (void)terminate;
  c->m.time = t + h;
  ModelOutputs(&c->m);
  return fmi3OK;
}

/* fmi3Get/Set<T> over field `field`, value references base and base + 1. */
#define ACCESS(Name, T, field, base)                                                        \
  EXPORT fmi3Status fmi3Get##Name(fmi3Instance c, const fmi3ValueReference vr[], size_t n, \
                                  T v[], size_t nv) {                                       \
    Model* m = &((Instance*)c)->m;                                                          \
    if (n != nv) return fmi3Error;                                                          \
    FMI3_CHECK_GET("fmi3Get" #Name)                                                          \
    ModelOutputs(m);                                                                        \
    for (size_t k = 0; k < n; ++k) {                                                        \
      if (vr[k] < (base) || vr[k] > (base) + 1) return fmi3Error;                           \
      v[k] = m->field[vr[k] - (base)];                                                      \
    }                                                                                       \
    return fmi3OK;                                                                          \
  }                                                                                         \
  EXPORT fmi3Status fmi3Set##Name(fmi3Instance c, const fmi3ValueReference vr[], size_t n, \
                                  const T v[], size_t nv) {                                 \
    Model* m = &((Instance*)c)->m;                                                          \
    if (n != nv) return fmi3Error;                                                          \
    FMI3_NOTE_SET()                                                                         \
    for (size_t k = 0; k < n; ++k) {                                                        \
      if (vr[k] != (base)) return fmi3Error; /* inputs only */                              \
      m->field[0] = v[k];                                                                   \
    }                                                                                       \
    return fmi3OK;                                                                          \
  }

ACCESS(Float32, float, f32, 400)
ACCESS(Int8, int8_t, i8, 410)
ACCESS(UInt8, uint8_t, u8, 420)
ACCESS(Int16, int16_t, i16, 430)
ACCESS(UInt16, uint16_t, u16, 440)
ACCESS(UInt32, uint32_t, u32, 450)
/* Int64: the pair at 460 and the enumeration pair at 480 (enumerations
 * travel as Int64, FMI 3.0 section 2.4.7.5). */
static int64_t* Int64Slot(Model* m, fmi3ValueReference vr) {
  if (vr == 460 || vr == 461) return &m->i64[vr - 460];
  if (vr == 480 || vr == 481) return &m->e[vr - 480];
  return NULL;
}
EXPORT fmi3Status fmi3GetInt64(fmi3Instance c, const fmi3ValueReference vr[], size_t n,
                               int64_t v[], size_t nv) {
  Model* m = &((Instance*)c)->m;
  if (n != nv) return fmi3Error;
  FMI3_CHECK_GET("fmi3GetInt64")
  ModelOutputs(m);
  for (size_t k = 0; k < n; ++k) {
    int64_t* slot = Int64Slot(m, vr[k]);
    if (!slot) return fmi3Error;
    v[k] = *slot;
  }
  return fmi3OK;
}
EXPORT fmi3Status fmi3SetInt64(fmi3Instance c, const fmi3ValueReference vr[], size_t n,
                               const int64_t v[], size_t nv) {
  Model* m = &((Instance*)c)->m;
  if (n != nv) return fmi3Error;
  FMI3_NOTE_SET()
  for (size_t k = 0; k < n; ++k) {
    if (vr[k] != 460 && vr[k] != 480) return fmi3Error; /* inputs only */
    *Int64Slot(m, vr[k]) = v[k];
  }
  return fmi3OK;
}

/* UInt64: the pair at 470 and the structural parameter n (vr 500) = 3. */
EXPORT fmi3Status fmi3GetUInt64(fmi3Instance c, const fmi3ValueReference vr[], size_t n,
                                uint64_t v[], size_t nv) {
  Model* m = &((Instance*)c)->m;
  if (n != nv) return fmi3Error;
  FMI3_CHECK_GET("fmi3GetUInt64")
  ModelOutputs(m);
  for (size_t k = 0; k < n; ++k) {
    if (vr[k] == 500) {
      v[k] = 3;
    } else if (vr[k] == 470 || vr[k] == 471) {
      v[k] = m->u64[vr[k] - 470];
    } else {
      return fmi3Error;
    }
  }
  return fmi3OK;
}
EXPORT fmi3Status fmi3SetUInt64(fmi3Instance c, const fmi3ValueReference vr[], size_t n,
                                const uint64_t v[], size_t nv) {
  Model* m = &((Instance*)c)->m;
  if (n != nv) return fmi3Error;
  FMI3_NOTE_SET()
  for (size_t k = 0; k < n; ++k) {
    if (vr[k] == 500) {
      if (v[k] != 3) return fmi3Error;
    } else if (vr[k] == 470) {
      m->u64[0] = v[k];
    } else {
      return fmi3Error;
    }
  }
  return fmi3OK;
}

/* Binary: the input at 490, the output at 491 (its copy). */
EXPORT fmi3Status fmi3GetBinary(fmi3Instance c, const fmi3ValueReference vr[], size_t n,
                                size_t sizes[], const fmi3Byte* v[], size_t nv) {
  Model* m = &((Instance*)c)->m;
  if (n != nv) return fmi3Error;
  FMI3_CHECK_GET("fmi3GetBinary")
  ModelOutputs(m);
  for (size_t k = 0; k < n; ++k) {
    if (vr[k] != 490 && vr[k] != 491) return fmi3Error;
    sizes[k] = m->blob_size[vr[k] - 490];
    v[k] = m->blob[vr[k] - 490];
  }
  return fmi3OK;
}
EXPORT fmi3Status fmi3SetBinary(fmi3Instance c, const fmi3ValueReference vr[], size_t n,
                                const size_t sizes[], const fmi3Byte* const v[], size_t nv) {
  Model* m = &((Instance*)c)->m;
  if (n != nv) return fmi3Error;
  FMI3_NOTE_SET()
  for (size_t k = 0; k < n; ++k) {
    if (vr[k] != 490 || sizes[k] > BLOB_MAX) return fmi3Error; /* the input only */
    memcpy(m->blob[0], v[k], sizes[k]);
    m->blob_size[0] = sizes[k];
  }
  return fmi3OK;
}
