/* gige_net.h - what the GigE Vision output does on the network beside
 * Aravis's device (output_gige.c). Internal to the gige driver. */
#ifndef NC_GIGE_NET_H
#define NC_GIGE_NET_H

/* Aravis 0.8's device checks its controller's heartbeat only when a control
 * message arrives: a client that dies keeps the control, and the stream,
 * while no one else talks to the device. nc__gige_probe sends the device
 * (at addr, UDP 3956) one read of its version register, which makes it
 * check, and drops any answers waiting. Returns the probe's socket, or -1. */
int nc__gige_probe_open(const char *addr);
void nc__gige_probe(int fd);

/* Aravis's device also listens on 255.255.255.255:3956, which takes
 * discovery broadcasts from every interface. For a device on loopback,
 * nc__gige_quiet_discovery replaces each such socket not among before[]
 * (the ones that existed before the device started) with an unbound one
 * that never receives; nc__gige_discovery_fds lists them. */
int nc__gige_discovery_fds(int *fds, int max);
void nc__gige_quiet_discovery(const int *before, int nbefore);

#endif
