/* test_fs.c - directories made with their parents and files put in place
 * whole (core/fs.h): what is made, what is refused, and that a refusal
 * names the path and leaves what was there. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/error.h"
#include "core/fs.h"
#include "testutil.h"

static int is_dir(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0 && S_ISDIR(st.st_mode);
}

int main(void)
{
    char a[600], b[600], f[600], tmp[600];
    snprintf(a, sizeof a, "%s/a/b/c", nc_test_tmp());
    CHECK(nc_mkdirs(a) == 0 && is_dir(a), "mkdirs %s: %s", a, nc_errmsg());
    CHECK(nc_mkdirs(a) == 0, "mkdirs of an existing directory: %s", nc_errmsg());
    snprintf(b, sizeof b, "%s/a/b/c/", nc_test_tmp());
    CHECK(nc_mkdirs(b) == 0, "a trailing slash: %s", nc_errmsg());
    /* an empty name is refused (it was taken for the current directory) */
    CHECK(nc_mkdirs("") == -ENOENT && nc_test_contains(nc_errmsg(), "empty"), "an empty name: %s", nc_errmsg());
    /* a file in the way: refused, named */
    snprintf(f, sizeof f, "%s/a/file", nc_test_tmp());
    nc_test_write(f, "x");
    snprintf(b, sizeof b, "%s/a/file/d", nc_test_tmp());
    CHECK(nc_mkdirs(b) == -ENOTDIR && nc_test_contains(nc_errmsg(), f), "a file in the path: %s", nc_errmsg());

    /* what a rename may replace: nothing, a regular file; not a directory or a device */
    snprintf(b, sizeof b, "%s/a/none", nc_test_tmp());
    CHECK(nc_fs_replaceable(b) == 0 && nc_fs_replaceable(f) == 0, "a missing path and a file are replaceable");
    CHECK(nc_fs_replaceable(a) == -EEXIST && nc_test_contains(nc_errmsg(), "a directory"), "a directory: %s",
          nc_errmsg());
    CHECK(nc_fs_replaceable("/dev/null") == -EEXIST && nc_test_contains(nc_errmsg(), "device"), "/dev/null: %s",
          nc_errmsg());

    /* a file put in place whole: the temporary's bytes under the name, the temporary gone */
    snprintf(tmp, sizeof tmp, "%s/a/.file.tmp", nc_test_tmp());
    nc_test_write(tmp, "whole");
    CHECK(nc_commit_file(tmp, f) == 0, "commit: %s", nc_errmsg());
    size_t len = 0;
    char *got = nc_test_read(f, &len);
    struct stat st;
    CHECK(got && len == 5 && !memcmp(got, "whole", 5) && stat(tmp, &st) < 0, "the committed file: %.*s",
          (int)len, got ? got : "");
    free(got);
    /* not over a directory: refused, the temporary kept */
    nc_test_write(tmp, "again");
    CHECK(nc_commit_file(tmp, a) == -EEXIST && stat(tmp, &st) == 0 && is_dir(a), "commit over a directory: %s",
          nc_errmsg());

    /* a row's temporaries dropped, and nothing else: its files, its lock, other rows' */
    static const char *const drop[] = {".frame_000005.tmp.fits", "..frame_000005.tmp.4242.tmp.fits",
                                       ".frame_000005_geometry.tmp.fits", ".frame_000005.json.tmp"};
    static const char *const keep[] = {"frame_000005.fits", ".frame_000005.lock", ".frame_0000050.tmp.fits",
                                       ".frame_000006.tmp.fits", "frame_000005.tmp.fits"};
    char d[600], p[700];
    snprintf(d, sizeof d, "%s/rows", nc_test_tmp());
    CHECK(nc_mkdirs(d) == 0, "mkdirs %s", d);
    for (int i = 0; i < 9; i++) {
        snprintf(p, sizeof p, "%s/%s", d, i < 4 ? drop[i] : keep[i - 4]);
        nc_test_write(p, "x");
    }
    const int n = nc_fs_drop_temporaries(d, "frame_000005");
    int kept = 0, gone = 0;
    for (int i = 0; i < 9; i++) {
        snprintf(p, sizeof p, "%s/%s", d, i < 4 ? drop[i] : keep[i - 4]);
        *(i < 4 ? &gone : &kept) += (stat(p, &st) == 0) == (i >= 4);
    }
    CHECK(n == 4 && gone == 4 && kept == 5, "a row's temporaries: %d dropped, %d of 4 gone, %d of 5 kept", n, gone,
          kept);

    /* a lock: 1 when made, 2 when its file was left by a holder that did not finish, 0 while held */
    snprintf(p, sizeof p, "%s/.row.lock", d);
    int fd, fd2;
    CHECK(nc_fs_lock(p, &fd) == 1, "a new lock");
    CHECK(nc_fs_lock(p, &fd2) == 0, "a lock held elsewhere");
    nc_fs_unlock(p, fd, 0); /* unfinished: the file stays */
    CHECK(nc_fs_lock(p, &fd) == 2, "a lock left unfinished");
    nc_fs_unlock(p, fd, 1);
    CHECK(stat(p, &st) < 0 && nc_fs_lock(p, &fd) == 1, "a lock removed when done, then new again");
    nc_fs_unlock(p, fd, 1);
    return nc_test_end();
}
