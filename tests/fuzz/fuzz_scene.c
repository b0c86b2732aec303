/*
** fuzz_scene.c — the libFuzzer target: bytes to a scene (gen.c), run
** in-process in a sandboxed state with limits (runner.c), under ASan and
** UBSan. Outputs go to a temporary folder emptied after every input; a
** temporary file left there, or a file beside it, is a finding (abort).
** OCFUZZ_SKIP leaves parts of the grammar out (see gen.h).
*/
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "gen.h"
#include "runner.h"

static ocfz_dirs dirs;
static int skip;

static void remove_dirs(void) {
  ocfz_dirs_close(&dirs);
}

int LLVMFuzzerInitialize(int *argc, char ***argv) {
  (void)argc;
  (void)argv;
  if (ocfz_dirs_open(&dirs, "ocfuzz") != 0) {
    perror("fuzz_scene: output folder");
    exit(2);
  }
  atexit(remove_dirs);
  skip = ocfz_skip_from_env();
  return 0;
}

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size) {
  static const ocfz_limits lim = {64u << 20, 2000, NULL, NULL, NULL, NULL};
  char msg[256];
  size_t len = 0;
  char *scene = ocfz_scene(data, size, skip, &len);
  if (scene == NULL) return 0;
  ocfz_run(scene, len, dirs.out, &lim, msg, sizeof msg);
  free(scene);
  if (!ocfz_dirs_check(&dirs, msg, sizeof msg)) {
    fprintf(stderr, "fuzz_scene: the scene left '%s' behind\n", msg);
    abort(); /* a finding */
  }
  return 0;
}
