/*
** main.c — entry point of the `outcrop` interpreter: parse the command
** line, run the scene, exit with its status (see ocrt.h for the values).
*/
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <unistd.h>

#include "ocrt.h"

/* A standard descriptor closed at startup would be reused by the first
** file the scene opens, and print would then write into that file: hold
** each with /dev/null, read-only, so writes still fail as on a closed one
** (and the status says so, below). */
static void hold_std_fds(void) {
  int fd, got;
  for (fd = 0; fd <= 2; fd++) {
    if (fcntl(fd, F_GETFD) != -1 || errno != EBADF) continue;
    got = open("/dev/null", O_RDONLY);
    if (got >= 0 && got != fd) close(got);
  }
}

int main(int argc, char **argv) {
  ocrt_options o;
  int status;
  hold_std_fds();
  status = ocrt_parse(&o, argc, argv);
  if (status != OCRT_RUN) return status;
  status = ocrt_run(&o);
  ocrt_options_free(&o);
  /* print ignores write errors: an earlier failure shows in ferror */
  if (fflush(stdout) != 0) {
    perror("outcrop: writing standard output");
  } else if (ferror(stdout)) {
    fputs("outcrop: writing standard output failed\n", stderr);
  } else {
    return status;
  }
  return status == OCRT_OK ? OCRT_ESCRIPT : status;
}
