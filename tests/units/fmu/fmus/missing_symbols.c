/* A binary that exports only part of the FMI 2.0 functions (no
 * fmi2DoStep): an FMU with it must be refused naming the symbol. */
#define EXPORT __attribute__((visibility("default")))
EXPORT const char* fmi2GetVersion(void) { return "2.0"; }
EXPORT void* fmi2Instantiate(void) { return 0; }
