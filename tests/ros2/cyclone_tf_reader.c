/* A ROS 2 node's view of /tf_static through Eclipse Cyclone DDS, the DDS of
 * ROS 2's rmw_cyclonedds: topic rt/tf_static, tf2_ros's static listener QoS
 * (reliable, transient local, keep last 100), types from ROS 2's .msg files
 * (ros2_messages.idl). The discovery settings come from CYCLONEDDS_URI, as
 * rmw_cyclonedds builds them for each ROS 2 discovery setting.
 *
 * Usage: cyclone_tf_reader DOMAIN TRANSFORMS SECONDS
 * Prints each sample that arrives as one JSON line; exits 0 once a sample
 * holds TRANSFORMS transforms, 1 if none did within SECONDS, 2 on bad use. */
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "dds/dds.h"
#include "ros2_messages.h"

static double now_s(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static void print_sample(const tf2_msgs_msg_dds__TFMessage_* m) {
  printf("{\"transforms\": [");
  for (uint32_t i = 0; i < m->transforms._length; ++i) {
    const geometry_msgs_msg_dds__TransformStamped_* t = &m->transforms._buffer[i];
    printf("%s{\"parent\": \"%s\", \"child\": \"%s\", \"sec\": %d, \"nanosec\": %u, "
           "\"x\": %.17g, \"y\": %.17g, \"z\": %.17g, \"qx\": %.17g, \"qy\": %.17g, \"qz\": %.17g, \"qw\": %.17g}",
           i ? ", " : "", t->header.frame_id, t->child_frame_id, t->header.stamp.sec, t->header.stamp.nanosec,
           t->transform.translation.x, t->transform.translation.y, t->transform.translation.z,
           t->transform.rotation.x, t->transform.rotation.y, t->transform.rotation.z, t->transform.rotation.w);
  }
  printf("]}\n");
  fflush(stdout);
}

int main(int argc, char** argv) {
  if (argc != 4) {
    fprintf(stderr, "usage: %s DOMAIN TRANSFORMS SECONDS\n", argv[0]);
    return 2;
  }
  const dds_domainid_t domain = (dds_domainid_t)atoi(argv[1]);
  const uint32_t wanted = (uint32_t)atoi(argv[2]);
  const double deadline = now_s() + atof(argv[3]);

  const dds_entity_t participant = dds_create_participant(domain, NULL, NULL);
  if (participant < 0) {
    fprintf(stderr, "dds_create_participant: %s\n", dds_strretcode(-participant));
    return 2;
  }
  const dds_entity_t topic =
      dds_create_topic(participant, &tf2_msgs_msg_dds__TFMessage__desc, "rt/tf_static", NULL, NULL);
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_durability(qos, DDS_DURABILITY_TRANSIENT_LOCAL);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 100);
  const dds_entity_t reader = dds_create_reader(participant, topic, qos, NULL);
  dds_delete_qos(qos);
  if (topic < 0 || reader < 0) {
    fprintf(stderr, "cannot create the rt/tf_static reader\n");
    dds_delete(participant);
    return 2;
  }

  int found = 0;
  while (!found && now_s() < deadline) {
    void* samples[1] = {NULL};
    dds_sample_info_t infos[1];
    const dds_return_t n = dds_take(reader, samples, infos, 1, 1);
    if (n > 0) {
      if (infos[0].valid_data) {
        const tf2_msgs_msg_dds__TFMessage_* m = samples[0];
        print_sample(m);
        found = m->transforms._length >= wanted;
      }
      dds_return_loan(reader, samples, n);
    } else {
      dds_sleepfor(DDS_MSECS(20));
    }
  }
  dds_delete(participant);
  if (!found) fprintf(stderr, "no sample with %u transforms on rt/tf_static within %s s\n", wanted, argv[3]);
  return found ? 0 : 1;
}
