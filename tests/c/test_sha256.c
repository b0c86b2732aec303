/*
** test_sha256.c — SHA-256 (lib/core/sha256.h) against the FIPS 180-2
** example vectors ("abc", the two-block message, a million 'a') and the
** empty message; padding at the block boundaries; the same digest
** whatever the update lengths; oc_infile_sha256 on a file, a folder and a
** FIFO (refused without blocking).
*/
#include <check.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/sha256.h"
#include "io/infile.h"

static void check_text(const char *msg, size_t n, const char *want) {
  char hex[OC_SHA256_HEX];
  oc_sha256_text(msg, n, hex);
  ck_assert_str_eq(hex, want);
}

START_TEST(standard_vectors) {
  check_text(
      "", 0,
      "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  check_text(
      "abc", 3,
      "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  const char *two = "abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq";
  check_text(
      two, strlen(two),
      "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
}
END_TEST

START_TEST(million_a) {
  oc_sha256 s;
  unsigned char d[OC_SHA256_BYTES], chunk[1000];
  char hex[OC_SHA256_HEX];
  memset(chunk, 'a', sizeof chunk);
  oc_sha256_init(&s);
  for (int i = 0; i < 1000; i++)
    oc_sha256_update(&s, chunk, sizeof chunk);
  oc_sha256_final(&s, d);
  oc_sha256_hex(d, hex);
  ck_assert_str_eq(
      hex, "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}
END_TEST

/* Lengths where the padding needs one more block or just fits
** (digests from an independent implementation, Python's hashlib). */
START_TEST(padding_boundaries) {
  static const struct {
    size_t n;
    const char *hex;
  } v[] = {
      {55, "9f4390f8d30c2dd92ec9f095b65e2b9ae9b0a925a5258e241c9f1e910f734318"},
      {56, "b35439a4ac6f0948b6d6f9e3c6af0f5f590ce20f1bde7090ef7970686ec6738a"},
      {63, "7d3e74a05d7db15bce4ad9ec0658ea98e3f06eeecf16b4c6fff2da457ddc2f34"},
      {64, "ffe054fe7ae0cb6dc65c3af9b61d5209f439851db43d0ba5997337df154668eb"},
      {119, "31eba51c313a5c08226adf18d4a359cfdfd8d2e816b13f4af952f7ea6584dcfb"},
      {120, "2f3d335432c70b580af0e8e1b3674a7c020d683aa5f73aaaedfdc55af904c21c"},
  };
  char a[128];
  memset(a, 'a', sizeof a);
  for (size_t i = 0; i < sizeof v / sizeof *v; i++)
    check_text(a, v[i].n, v[i].hex);
}
END_TEST

START_TEST(any_split_gives_the_same_digest) {
  unsigned char msg[300];
  for (size_t i = 0; i < sizeof msg; i++)
    msg[i] = (unsigned char)(i * 37 + 11);
  char whole[OC_SHA256_HEX], parts[OC_SHA256_HEX];
  oc_sha256_text(msg, sizeof msg, whole);
  for (size_t step = 1; step <= 130; step++) {
    oc_sha256 s;
    unsigned char d[OC_SHA256_BYTES];
    oc_sha256_init(&s);
    for (size_t at = 0; at < sizeof msg; at += step)
      oc_sha256_update(&s, msg + at,
                       sizeof msg - at < step ? sizeof msg - at : step);
    oc_sha256_final(&s, d);
    oc_sha256_hex(d, parts);
    ck_assert_msg(strcmp(whole, parts) == 0, "step %zu", step);
  }
}
END_TEST

START_TEST(files) {
  char dir[] = "/tmp/oc-sha256.XXXXXX";
  ck_assert_ptr_nonnull(mkdtemp(dir));
  char path[64], fifo[64], hex[OC_SHA256_HEX];
  oc_error err = {OC_OK, ""};
  snprintf(path, sizeof path, "%s/abc", dir);
  FILE *f = fopen(path, "wb");
  ck_assert_ptr_nonnull(f);
  /* more than one read buffer, so the loop runs more than once */
  for (int i = 0; i < 1000; i++)
    fputs("aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa"
          "aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa",
          f); /* 99 bytes, 99 000 in all */
  fclose(f);
  char want[OC_SHA256_HEX], *a = malloc(99000);
  memset(a, 'a', 99000);
  oc_sha256_text(a, 99000, want);
  free(a);
  ck_assert_int_eq(oc_infile_sha256(path, hex, &err), OC_OK);
  ck_assert_str_eq(hex, want);
  ck_assert_int_eq(oc_infile_sha256(dir, hex, &err), OC_EIO);
  ck_assert_ptr_nonnull(strstr(err.msg, "not a regular file (a folder)"));
  snprintf(fifo, sizeof fifo, "%s/fifo", dir);
  ck_assert_int_eq(mkfifo(fifo, 0600), 0);
  ck_assert_int_eq(oc_infile_sha256(fifo, hex, &err), OC_EIO);
  ck_assert_ptr_nonnull(strstr(err.msg, "a FIFO"));
  ck_assert_int_eq(oc_infile_sha256("/nonexistent/x", hex, &err), OC_EIO);
  ck_assert_ptr_nonnull(strstr(err.msg, "cannot read '/nonexistent/x'"));
  unlink(fifo);
  unlink(path);
  rmdir(dir);
}
END_TEST

int main(void) {
  setvbuf(stdout, NULL, _IOLBF, 0);
  Suite *s = suite_create("sha256");
  TCase *tc = tcase_create("sha256");
  tcase_add_test(tc, standard_vectors);
  tcase_add_test(tc, million_a);
  tcase_add_test(tc, padding_boundaries);
  tcase_add_test(tc, any_split_gives_the_same_digest);
  tcase_add_test(tc, files);
  suite_add_tcase(s, tc);
  SRunner *sr = srunner_create(s);
  srunner_run_all(sr, CK_NORMAL);
  int failed = srunner_ntests_failed(sr);
  srunner_free(sr);
  return failed ? 1 : 0;
}
