/* A ROS 2 node's view of tomomapd through Eclipse Cyclone DDS, the DDS of
 * ROS 2's rmw_cyclonedds, with types from ROS 2's .msg files
 * (ros2_messages.idl) and the QoS of the ROS 2 readers of each topic. The
 * discovery settings come from CYCLONEDDS_URI, as rmw_cyclonedds builds them
 * for each ROS 2 discovery setting.
 *
 * Usage: cyclone_ros2_reader tf_static DOMAIN TRANSFORMS SECONDS
 *          tf2_ros's static listener (reliable, transient local, keep last
 *          100); done once a sample holds TRANSFORMS transforms.
 *        cyclone_ros2_reader diagnostics DOMAIN KEY=VALUE SECONDS
 *          rqt_robot_monitor's (reliable, volatile, keep last 10); done once a
 *          status holds the value KEY = VALUE.
 * Prints each sample that arrives as one JSON line; exits 0 when done, 1 if
 * not within SECONDS, 2 on bad use. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "dds/dds.h"
#include "ros2_messages.h"

static double now_s(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Prints `s` as a JSON string (names and messages may hold quotes). */
static void print_string(const char* s) {
  putchar('"');
  for (; *s; ++s) {
    if (*s == '"' || *s == '\\') putchar('\\');
    if ((unsigned char)*s < 0x20)
      printf("\\u%04x", (unsigned char)*s);
    else
      putchar(*s);
  }
  putchar('"');
}

/* Prints a TFMessage; returns whether it holds `wanted` transforms or more. */
static int take_tf(const void* sample, const char* wanted) {
  const tf2_msgs_msg_dds__TFMessage_* m = sample;
  printf("{\"transforms\": [");
  for (uint32_t i = 0; i < m->transforms._length; ++i) {
    const geometry_msgs_msg_dds__TransformStamped_* t = &m->transforms._buffer[i];
    printf("%s{\"parent\": ", i ? ", " : "");
    print_string(t->header.frame_id);
    printf(", \"child\": ");
    print_string(t->child_frame_id);
    printf(
        ", \"sec\": %d, \"nanosec\": %u, \"x\": %.17g, \"y\": %.17g, \"z\": %.17g, "
        "\"qx\": %.17g, \"qy\": %.17g, \"qz\": %.17g, \"qw\": %.17g}",
        t->header.stamp.sec, t->header.stamp.nanosec, t->transform.translation.x, t->transform.translation.y,
        t->transform.translation.z, t->transform.rotation.x, t->transform.rotation.y, t->transform.rotation.z,
        t->transform.rotation.w);
  }
  printf("]}\n");
  return m->transforms._length >= (uint32_t)atoi(wanted);
}

/* Prints a DiagnosticArray; returns whether a status holds the value `wanted` (KEY=VALUE). */
static int take_diagnostics(const void* sample, const char* wanted) {
  const diagnostic_msgs_msg_dds__DiagnosticArray_* m = sample;
  const char* eq = strchr(wanted, '=');
  const size_t key_length = eq ? (size_t)(eq - wanted) : strlen(wanted);
  int found = 0;
  printf("{\"sec\": %d, \"status\": [", m->header.stamp.sec);
  for (uint32_t i = 0; i < m->status._length; ++i) {
    const diagnostic_msgs_msg_dds__DiagnosticStatus_* s = &m->status._buffer[i];
    printf("%s{\"level\": %u, \"name\": ", i ? ", " : "", (unsigned)s->level);
    print_string(s->name);
    printf(", \"message\": ");
    print_string(s->message);
    printf(", \"hardware_id\": ");
    print_string(s->hardware_id);
    printf(", \"values\": {");
    for (uint32_t k = 0; k < s->values._length; ++k) {
      const diagnostic_msgs_msg_dds__KeyValue_* kv = &s->values._buffer[k];
      printf("%s", k ? ", " : "");
      print_string(kv->key);
      printf(": ");
      print_string(kv->value);
      found |= eq && strlen(kv->key) == key_length && strncmp(kv->key, wanted, key_length) == 0 &&
               strcmp(kv->value, eq + 1) == 0;
    }
    printf("}}");
  }
  printf("]}\n");
  return found;
}

int main(int argc, char** argv) {
  const int tf = argc == 5 && strcmp(argv[1], "tf_static") == 0;
  const int diagnostics = argc == 5 && strcmp(argv[1], "diagnostics") == 0;
  if (!tf && !diagnostics) {
    fprintf(stderr, "usage: %s tf_static DOMAIN TRANSFORMS SECONDS | diagnostics DOMAIN KEY=VALUE SECONDS\n", argv[0]);
    return 2;
  }
  const double deadline = now_s() + atof(argv[4]);
  const dds_entity_t participant = dds_create_participant((dds_domainid_t)atoi(argv[2]), NULL, NULL);
  if (participant < 0) {
    fprintf(stderr, "dds_create_participant: %s\n", dds_strretcode(-participant));
    return 2;
  }
  const dds_entity_t topic =
      tf ? dds_create_topic(participant, &tf2_msgs_msg_dds__TFMessage__desc, "rt/tf_static", NULL, NULL)
         : dds_create_topic(participant, &diagnostic_msgs_msg_dds__DiagnosticArray__desc, "rt/diagnostics", NULL, NULL);
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_durability(qos, tf ? DDS_DURABILITY_TRANSIENT_LOCAL : DDS_DURABILITY_VOLATILE);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, tf ? 100 : 10);
  const dds_entity_t reader = dds_create_reader(participant, topic, qos, NULL);
  dds_delete_qos(qos);
  if (topic < 0 || reader < 0) {
    fprintf(stderr, "cannot create the reader of rt/%s\n", argv[1]);
    dds_delete(participant);
    return 2;
  }

  int done = 0;
  while (!done && now_s() < deadline) {
    void* samples[1] = {NULL};
    dds_sample_info_t infos[1];
    const dds_return_t n = dds_take(reader, samples, infos, 1, 1);
    if (n > 0) {
      if (infos[0].valid_data) done = tf ? take_tf(samples[0], argv[3]) : take_diagnostics(samples[0], argv[3]);
      fflush(stdout);
      dds_return_loan(reader, samples, n);
    } else {
      dds_sleepfor(DDS_MSECS(20));
    }
  }
  dds_delete(participant);
  if (!done) fprintf(stderr, "nothing on rt/%s with %s within %s s\n", argv[1], argv[3], argv[4]);
  return done ? 0 : 1;
}
