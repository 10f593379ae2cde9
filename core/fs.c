/* fs.c - directories and files that must survive a crash (fs.h). */
#include "core/fs.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/error.h"

int nc_mkdirs(const char *dir)
{
    char d[4096];
    if (snprintf(d, sizeof d, "%s", dir) >= (int)sizeof d)
        return nc_error(-ENAMETOOLONG, "%s: path too long", dir);
    if (!d[0])
        return nc_error(-ENOENT, "an empty directory name");
    for (char *p = d + 1;; p++) {
        const char c = *p;
        if (c != '/' && c != '\0')
            continue;
        *p = '\0';
        if (mkdir(d, 0777) < 0 && errno != EEXIST)
            return nc_error(-errno, "cannot make %s: %s", d, strerror(errno));
        *p = c;
        if (!c)
            return 0;
    }
}

/* fsync of path (a file or a directory) */
static int sync_path(const char *path)
{
    const int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        return nc_error(-errno, "%s: %s", path, strerror(errno));
    const int rc = fsync(fd) < 0 && errno != EINVAL ? -errno : 0; /* EINVAL: a file system without fsync */
    close(fd);
    return rc < 0 ? nc_error(rc, "%s: fsync: %s", path, strerror(-rc)) : 0;
}

int nc_fs_replaceable(const char *path)
{
    struct stat st;
    if (lstat(path, &st) < 0 || S_ISREG(st.st_mode) || S_ISLNK(st.st_mode))
        return 0;
    return nc_error(-EEXIST, "%s: exists and is not a regular file (%s): not replaced", path,
                    S_ISDIR(st.st_mode) ? "a directory" : "a device, pipe or socket");
}

int nc_commit_file(const char *tmp, const char *path)
{
    int rc = nc_fs_replaceable(path);
    if (rc < 0)
        return rc;
    rc = sync_path(tmp);
    if (rc < 0)
        return rc;
    if (rename(tmp, path) < 0)
        return nc_error(-errno, "%s: rename to %s: %s", tmp, path, strerror(errno));
    char dir[4096];
    snprintf(dir, sizeof dir, "%s", path);
    char *slash = strrchr(dir, '/');
    if (!slash)
        snprintf(dir, sizeof dir, ".");
    else if (slash == dir)
        dir[1] = '\0';
    else
        *slash = '\0';
    return sync_path(dir);
}

int nc_fs_drop_temporaries(const char *dir, const char *stem)
{
    DIR *d = opendir(dir);
    if (!d)
        return 0;
    const size_t n = strlen(stem);
    int dropped = 0;
    for (struct dirent *e; (e = readdir(d));) {
        const char *name = e->d_name, *p = name + (name[0] == '.') + (name[0] == '.' && name[1] == '.');
        if (p == name || strncmp(p, stem, n) || (p[n] != '.' && p[n] != '_') || !strstr(p + n, ".tmp"))
            continue;
        char path[4200];
        snprintf(path, sizeof path, "%s/%s", dir, name);
        dropped += unlink(path) == 0;
    }
    closedir(d);
    return dropped;
}

int nc_fs_lock(const char *path, int *fd)
{
    struct stat st;
    const int stale = stat(path, &st) == 0;
    if ((*fd = open(path, O_RDWR | O_CREAT | O_CLOEXEC, 0666)) < 0)
        return nc_error(-errno, "%s: %s", path, strerror(errno));
    if (flock(*fd, LOCK_EX | LOCK_NB) == 0)
        return 1 + stale;
    const int err = errno;
    close(*fd);
    return err == EWOULDBLOCK ? 0 : nc_error(-err, "%s: flock: %s", path, strerror(err));
}

void nc_fs_unlock(const char *path, int fd, int done)
{
    if (done)
        unlink(path);
    close(fd);
}
