/* fs.h - directories and files that must survive a crash: a directory
 * made with its missing parents, and a file put in place whole. */
#ifndef NC_FS_H
#define NC_FS_H

/* Make dir and every missing parent, as mkdir -p (0777 less the umask).
 * 0, or -errno with a message naming the directory that could not be
 * made. */
int nc_mkdirs(const char *dir);

/* Whether a file put in place by rename may replace what is at path: 0 for
 * nothing there, a regular file or a symbolic link (the link itself is
 * replaced, not its target); -EEXIST with a message for a directory, a
 * device, a pipe or a socket (as root, a rename would replace /dev/null). */
int nc_fs_replaceable(const char *path);

/* Put the complete file tmp in place as path (nc_fs_replaceable first): its data flushed to the disk
 * (fsync), renamed, and the rename flushed (fsync of path's directory), so
 * that after a crash or a power cut path is either absent or whole. 0, or
 * -errno with a message naming the file. */
int nc_commit_file(const char *tmp, const char *path);

/* An exclusive lock (flock) on the file path, made if missing: 1 with *fd
 * holding it, 2 the same where the file was there already (a holder that
 * crashed, or one that let it go without removing it: what it was doing is
 * unfinished), 0 if another process holds it, < 0 on error. Released by
 * nc_fs_unlock, which removes the file if done (the work is finished). */
int nc_fs_lock(const char *path, int *fd);
void nc_fs_unlock(const char *path, int fd, int done);

/* Remove the temporaries a crash may have left of the files named stem in
 * dir: a hidden name (one dot or two: a temporary's own temporary) made of
 * stem, then '.' or '_', holding ".tmp" ("DIR/.frame_000005.tmp.fits",
 * "DIR/..frame_000005.tmp.4242.tmp.fits"). How many; errors are ignored. */
int nc_fs_drop_temporaries(const char *dir, const char *stem);

#endif
