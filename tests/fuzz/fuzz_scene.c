/*
** fuzz_scene.c — the libFuzzer target: bytes to a scene (gen.c), run
** in-process in a sandboxed state with limits (runner.c), under ASan and
** UBSan. Outputs go to a temporary folder emptied after every input.
** OCFUZZ_SKIP leaves parts of the grammar out (see gen.h).
*/
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "gen.h"
#include "runner.h"

static char outdir[] = "/tmp/ocfuzz.XXXXXX";
static int skip;

static void remove_outdir(void) {
  ocfz_clean(outdir);
  rmdir(outdir);
}

int LLVMFuzzerInitialize(int *argc, char ***argv) {
  (void)argc;
  (void)argv;
  if (mkdtemp(outdir) == NULL) {
    perror("fuzz_scene: mkdtemp");
    exit(2);
  }
  atexit(remove_outdir);
  skip = ocfz_skip_from_env();
  return 0;
}

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size) {
  static const ocfz_limits lim = {64u << 20, 2000, NULL, NULL, NULL, NULL};
  char msg[256];
  size_t len = 0;
  char *scene = ocfz_scene(data, size, skip, &len);
  if (scene == NULL) return 0;
  ocfz_run(scene, len, outdir, &lim, msg, sizeof msg);
  free(scene);
  ocfz_clean(outdir);
  return 0;
}
