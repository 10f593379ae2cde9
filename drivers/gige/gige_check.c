/* gige_check.c - what the GigE Vision output checks before it starts
 * Aravis's device, which reports neither a taken port nor a broken GenICam
 * description (gige_check.h). */
#include "drivers/gige/gige_check.h"

#include <arpa/inet.h>
#include <arv.h>
#include <errno.h>
#include <ifaddrs.h>
#include <net/if.h>
#include <netinet/in.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "core/error.h"

/* The interface's IPv4 address, and whether the GigE Vision control port is
 * free there (Aravis does not report a taken port: its device just goes
 * deaf). */
int nc__gige_check_interface(const char *iface, struct nc_cfg_node *where, char *addr, size_t addr_len)
{
    struct ifaddrs *ifa = NULL;
    if (if_nametoindex(iface) == 0)
        return nc_cfg_error(where, "gige: network interface '%s' not found", iface);
    if (getifaddrs(&ifa) < 0)
        return nc_error(-errno, "gige: getifaddrs: %s", strerror(errno));
    struct sockaddr_in sa = {0};
    for (struct ifaddrs *i = ifa; i; i = i->ifa_next)
        if (i->ifa_addr && i->ifa_addr->sa_family == AF_INET && !strcmp(i->ifa_name, iface)) {
            sa = *(struct sockaddr_in *)i->ifa_addr;
            break;
        }
    freeifaddrs(ifa);
    if (sa.sin_family != AF_INET)
        return nc_error(NC_ECONFIG, "gige: interface '%s' has no IPv4 address", iface);
    inet_ntop(AF_INET, &sa.sin_addr, addr, addr_len);
    int fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sa.sin_port = htons(3956);
    int rc = 0;
    if (fd < 0 || bind(fd, (struct sockaddr *)&sa, sizeof sa) < 0)
        rc = nc_error(errno == EADDRINUSE ? NC_ECONFIG : -errno,
                      "gige: UDP port 3956 (GigE Vision control) on %s (%s) is %s", addr, iface,
                      errno == EADDRINUSE ? "already in use: another GigE Vision device (or navcam serve) runs there"
                                          : strerror(errno));
    if (fd >= 0)
        close(fd);
    return rc;
}

/* A GenICam description must parse and name the features NavCam serves. */
int nc__gige_check_xml(const char *what, const void *xml, size_t len)
{
    static const char *const need[] = {"Width", "Height", "OffsetX", "OffsetY", "PixelFormat", "PayloadSize",
                                       "ExposureTime", "Gain", "AcquisitionStart", "AcquisitionStop", "TriggerMode",
                                       "TriggerSource", "TriggerSoftware", "AcquisitionFrameRate", NULL};
    ArvGc *gc = arv_gc_new(NULL, xml, len);
    int rc = 0;
    for (int i = 0; need[i] && rc == 0; i++)
        if (!gc || !arv_gc_get_node(gc, need[i]))
            rc = nc_error(NC_ECONFIG, "gige: GenICam XML %s is invalid: it %s feature '%s' NavCam serves", what,
                          gc ? "does not parse (messages above) or lacks the" : "does not parse, so it lacks the",
                          need[i]);
    if (gc)
        g_object_unref(gc);
    return rc;
}
