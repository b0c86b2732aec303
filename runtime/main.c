/*
** main.c — entry point of the `outcrop` interpreter: parse the command
** line, run the scene, exit with its status (see ocrt.h for the values).
*/
#include <stdio.h>

#include "ocrt.h"

int main(int argc, char **argv) {
  ocrt_options o;
  int status = ocrt_parse(&o, argc, argv);
  if (status != OCRT_RUN) return status;
  status = ocrt_run(&o);
  ocrt_options_free(&o);
  if (fflush(stdout) != 0 && status == OCRT_OK) {
    perror("outcrop: writing standard output");
    status = OCRT_ESCRIPT;
  }
  return status;
}
