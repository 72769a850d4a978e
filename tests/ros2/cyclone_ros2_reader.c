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
 *        cyclone_ros2_reader fleet_map DOMAIN ROBOTS SECONDS
 *          RViz's map cloud display (reliable, transient local, keep last 1);
 *          done once a PointCloud2 holds points of ROBOTS labels (robots) or more.
 *        cyclone_ros2_reader fleet_map_grid DOMAIN OCCUPIED SECONDS
 *          a map display or a costmap's static layer (the same QoS); done once an
 *          OccupancyGrid holds OCCUPIED occupied cells or more.
 * Prints each sample that arrives as one JSON line, with its publisher's
 * USER_DATA (where ROS 2 endpoints carry their type hash); exits 0 when done,
 * 1 if not within SECONDS, 2 on bad use. */
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
  printf("]");
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
  printf("]");
  return found;
}

/* Prints a PointCloud2's layout, its points per label (the robot) and their
 * bounds; returns whether `wanted` labels or more have points. */
static int take_cloud(const void* sample, const char* wanted) {
  const sensor_msgs_msg_dds__PointCloud2_* m = sample;
  printf("{\"frame_id\": ");
  print_string(m->header.frame_id);
  printf(", \"sec\": %d, \"width\": %u, \"height\": %u, \"point_step\": %u, \"row_step\": %u, \"bytes\": %u, "
         "\"fields\": [",
         m->header.stamp.sec, m->width, m->height, m->point_step, m->row_step, m->data._length);
  int32_t x = -1, label = -1;
  for (uint32_t i = 0; i < m->fields._length; ++i) {
    const sensor_msgs_msg_dds__PointField_* f = &m->fields._buffer[i];
    printf("%s{\"name\": ", i ? ", " : "");
    print_string(f->name);
    printf(", \"offset\": %u, \"datatype\": %u, \"count\": %u}", f->offset, (unsigned)f->datatype, f->count);
    if (strcmp(f->name, "x") == 0 && f->datatype == 7) x = (int32_t)f->offset;
    if (strcmp(f->name, "label") == 0 && f->datatype == 6) label = (int32_t)f->offset;
  }
  printf("]");
  const uint32_t points = m->width * m->height;
  int robots = 0;
  if (x >= 0 && label >= 0 && (uint64_t)points * m->point_step <= m->data._length) {
    uint32_t per_label[16] = {0};
    float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
    for (uint32_t i = 0; i < points; ++i) {
      const uint8_t* p = m->data._buffer + (size_t)i * m->point_step;
      float xyz[3];
      uint32_t l;
      memcpy(xyz, p + x, sizeof xyz);
      memcpy(&l, p + label, sizeof l);
      if (l < 16) ++per_label[l];
      for (int k = 0; k < 3; ++k) {
        if (xyz[k] < lo[k]) lo[k] = xyz[k];
        if (xyz[k] > hi[k]) hi[k] = xyz[k];
      }
    }
    printf(", \"per_label\": [");
    for (int l = 0; l < 16; ++l) {
      printf("%s%u", l ? ", " : "", per_label[l]);
      robots += per_label[l] > 0;
    }
    printf("], \"min\": [%g, %g, %g], \"max\": [%g, %g, %g]", lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
  }
  return robots >= atoi(wanted);
}

/* Prints an OccupancyGrid's metadata and its cells by value; returns whether
 * `wanted` of them or more are occupied. */
static int take_grid(const void* sample, const char* wanted) {
  const nav_msgs_msg_dds__OccupancyGrid_* m = sample;
  const nav_msgs_msg_dds__MapMetaData_* info = &m->info;
  uint32_t occupied = 0, free_cells = 0, unknown = 0, other = 0;
  for (uint32_t i = 0; i < m->data._length; ++i) {
    const int8_t v = m->data._buffer[i];
    if (v == 100) ++occupied;
    else if (v == 0) ++free_cells;
    else if (v == -1) ++unknown;
    else ++other;
  }
  printf("{\"frame_id\": ");
  print_string(m->header.frame_id);
  printf(", \"sec\": %d, \"resolution\": %.9g, \"width\": %u, \"height\": %u, \"cells\": %u, "
         "\"origin\": {\"x\": %.17g, \"y\": %.17g, \"z\": %.17g, \"qx\": %.17g, \"qy\": %.17g, \"qz\": %.17g, "
         "\"qw\": %.17g}, \"occupied\": %u, \"free\": %u, \"unknown\": %u, \"other\": %u",
         m->header.stamp.sec, (double)info->resolution, info->width, info->height, m->data._length,
         info->origin.position.x, info->origin.position.y, info->origin.position.z, info->origin.orientation.x,
         info->origin.orientation.y, info->origin.orientation.z, info->origin.orientation.w, occupied, free_cells,
         unknown, other);
  return occupied >= (uint32_t)atoi(wanted);
}

/* One way of reading: the topic, its type, the ROS 2 reader's QoS, and what to print. */
struct Mode {
  const char* name;
  const char* topic;
  const dds_topic_descriptor_t* type;
  int transient_local;
  int32_t depth;
  int (*take)(const void* sample, const char* wanted);
};

int main(int argc, char** argv) {
  const struct Mode modes[] = {
      {"tf_static", "rt/tf_static", &tf2_msgs_msg_dds__TFMessage__desc, 1, 100, take_tf},
      {"diagnostics", "rt/diagnostics", &diagnostic_msgs_msg_dds__DiagnosticArray__desc, 0, 10, take_diagnostics},
      {"fleet_map", "rt/fleet_map", &sensor_msgs_msg_dds__PointCloud2__desc, 1, 1, take_cloud},
      {"fleet_map_grid", "rt/fleet_map_grid", &nav_msgs_msg_dds__OccupancyGrid__desc, 1, 1, take_grid},
  };
  const struct Mode* mode = NULL;
  for (size_t i = 0; i < sizeof modes / sizeof modes[0]; ++i)
    if (argc == 5 && strcmp(argv[1], modes[i].name) == 0) mode = &modes[i];
  if (!mode) {
    fprintf(stderr,
            "usage: %s tf_static DOMAIN TRANSFORMS SECONDS | diagnostics DOMAIN KEY=VALUE SECONDS | "
            "fleet_map DOMAIN ROBOTS SECONDS | fleet_map_grid DOMAIN OCCUPIED SECONDS\n",
            argv[0]);
    return 2;
  }
  const double deadline = now_s() + atof(argv[4]);
  const dds_entity_t participant = dds_create_participant((dds_domainid_t)atoi(argv[2]), NULL, NULL);
  if (participant < 0) {
    fprintf(stderr, "dds_create_participant: %s\n", dds_strretcode(-participant));
    return 2;
  }
  const dds_entity_t topic = dds_create_topic(participant, mode->type, mode->topic, NULL, NULL);
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_durability(qos, mode->transient_local ? DDS_DURABILITY_TRANSIENT_LOCAL : DDS_DURABILITY_VOLATILE);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, mode->depth);
  const dds_entity_t reader = dds_create_reader(participant, topic, qos, NULL);
  dds_delete_qos(qos);
  if (topic < 0 || reader < 0) {
    fprintf(stderr, "cannot create the reader of %s\n", mode->topic);
    dds_delete(participant);
    return 2;
  }

  int done = 0;
  while (!done && now_s() < deadline) {
    void* samples[1] = {NULL};
    dds_sample_info_t infos[1];
    const dds_return_t n = dds_take(reader, samples, infos, 1, 1);
    if (n > 0) {
      if (infos[0].valid_data) {
        done = mode->take(samples[0], argv[3]);
        /* What rmw_cyclonedds reads the type hash from: the publisher's USER_DATA. */
        char user_data[256] = "";
        dds_builtintopic_endpoint_t* publisher = dds_get_matched_publication_data(reader, infos[0].publication_handle);
        if (publisher) {
          void* value = NULL;
          size_t size = 0;
          if (dds_qget_userdata(publisher->qos, &value, &size) && value) {
            snprintf(user_data, sizeof user_data, "%.*s", (int)size, (const char*)value);
            dds_free(value);
          }
          dds_builtintopic_free_endpoint(publisher);
        }
        printf(", \"user_data\": ");
        print_string(user_data);
        printf("}\n");
      }
      fflush(stdout);
      dds_return_loan(reader, samples, n);
    } else {
      dds_sleepfor(DDS_MSECS(20));
    }
  }
  dds_delete(participant);
  if (!done) fprintf(stderr, "nothing on %s with %s within %s s\n", mode->topic, argv[3], argv[4]);
  return done ? 0 : 1;
}
