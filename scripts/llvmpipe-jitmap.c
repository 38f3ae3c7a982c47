// LD_PRELOAD shim for profiling lavapipe with perf: names the functions llvmpipe compiles
// (fragment shaders "fs_variant_partial", vertex shaders, triangle setup), numbered in the order
// they were compiled, in /tmp/perf-PID.map, which perf reads for JIT code. With
// UMBRA_JITDUMP_DIR set, it also copies each function's machine code there after
// UMBRA_JITDUMP_DELAY seconds (default 3), for objdump. Used by scripts/profile-llvmpipe.sh.
#define _GNU_SOURCE
#include <dlfcn.h>
#include <fcntl.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

typedef void *LLVMExecutionEngineRef;
typedef void *LLVMValueRef;
extern const char *LLVMGetValueName2(LLVMValueRef, size_t *);

#define MAX_FUNCTIONS 4096
static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static FILE *map;
static uintptr_t addresses[MAX_FUNCTIONS];
static char names[MAX_FUNCTIONS][64];
static int count;

// Copies up to 128 KiB of each function's code (stopping at unmapped memory).
static void *dump_code(void *dir) {
  const char *delay = getenv("UMBRA_JITDUMP_DELAY");
  sleep(delay ? (unsigned)atoi(delay) : 3);
  pthread_mutex_lock(&lock);
  int mem = open("/proc/self/mem", O_RDONLY);
  for (int i = 0; mem >= 0 && i < count; i++) {
    char path[512];
    snprintf(path, sizeof path, "%s/%02d_%s_%lx.bin", (const char *)dir, i, names[i],
             (unsigned long)addresses[i]);
    FILE *out = fopen(path, "wb");
    unsigned char page[4096];
    for (int k = 0; out && k < 32; k++) {
      ssize_t n = pread(mem, page, sizeof page, (off_t)(addresses[i] + 4096u * k));
      if (n <= 0)
        break;
      fwrite(page, 1, (size_t)n, out);
    }
    if (out)
      fclose(out);
  }
  if (mem >= 0)
    close(mem);
  pthread_mutex_unlock(&lock);
  return NULL;
}

static void record(void *code, const char *name) {
  pthread_mutex_lock(&lock);
  if (!map) {
    char path[64];
    snprintf(path, sizeof path, "/tmp/perf-%d.map", getpid());
    map = fopen(path, "w");
    char *dir = getenv("UMBRA_JITDUMP_DIR");
    pthread_t t;
    if (dir && pthread_create(&t, NULL, dump_code, dir) == 0)
      pthread_detach(t);
  }
  if (map && code && count < MAX_FUNCTIONS) {
    // A provisional size; scripts/profile-llvmpipe.sh sets each to the gap to the next one.
    fprintf(map, "%lx 1000 %02d_%s\n", (unsigned long)(uintptr_t)code, count, name);
    fflush(map);
    addresses[count] = (uintptr_t)code;
    snprintf(names[count], sizeof names[count], "%s", name);
    count++;
  }
  pthread_mutex_unlock(&lock);
}

void *LLVMGetPointerToGlobal(LLVMExecutionEngineRef engine, LLVMValueRef global) {
  static void *(*real)(LLVMExecutionEngineRef, LLVMValueRef);
  if (!real)
    real = (void *(*)(LLVMExecutionEngineRef, LLVMValueRef))dlsym(RTLD_NEXT, "LLVMGetPointerToGlobal");
  void *code = real(engine, global);
  size_t length;
  record(code, LLVMGetValueName2(global, &length));
  return code;
}

uint64_t LLVMGetFunctionAddress(LLVMExecutionEngineRef engine, const char *name) {
  static uint64_t (*real)(LLVMExecutionEngineRef, const char *);
  if (!real)
    real = (uint64_t(*)(LLVMExecutionEngineRef, const char *))dlsym(RTLD_NEXT, "LLVMGetFunctionAddress");
  uint64_t code = real(engine, name);
  record((void *)(uintptr_t)code, name);
  return code;
}
