/* A SLAM package's map topic, as a ROS 2 node publishes it through Eclipse
 * Cyclone DDS (rmw_cyclonedds's DDS): sensor_msgs/PointCloud2 or
 * octomap_msgs/Octomap with types from ROS 2's .msg files
 * (ros2_messages.idl), reliable, transient local, keep last 1 (a latched map,
 * as octomap_server and RTAB-Map publish theirs).
 *
 * Usage: cyclone_cloud_publisher DOMAIN TOPIC POINTS LAYOUT FRAME SECONDS
 *   POINTS  a file of float32 x, y, z triples; for an Octomap, the tree's
 *           data as octomap_server puts it in the message
 *   LAYOUT  xyzi32: x, y, z, intensity as float32 (16 bytes a point, one row);
 *           xyz64: x, y, z as float64 and 8 bytes of padding (32 bytes a
 *           point), organised in two rows, the second padded by 16 bytes;
 *           octomap-binary@RES, octomap-full@RES: an Octomap of an OcTree of
 *           resolution RES [m], binary (occupancy) or full
 * Waits for a reader, publishes one message, and exits 0 once every matched
 * reader acknowledged it; 1 if none matched or acknowledged within SECONDS. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dds/dds.h"
#include "ros2_messages.h"

static int fail(const char* what) {
  fprintf(stderr, "cyclone_cloud_publisher: %s\n", what);
  return 2;
}

static void put_field(sensor_msgs_msg_dds__PointField_* f, const char* name, uint32_t offset, uint8_t datatype) {
  f->name = dds_string_dup(name);
  f->offset = offset;
  f->datatype = datatype;
  f->count = 1;
}

/* The whole of the file `path` (NULL if it cannot be read); its size in `*bytes`. */
static void* read_file(const char* path, long* bytes) {
  FILE* in = fopen(path, "rb");
  if (!in) return NULL;
  fseek(in, 0, SEEK_END);
  *bytes = ftell(in);
  fseek(in, 0, SEEK_SET);
  void* data = *bytes >= 0 ? malloc((size_t)*bytes + 1) : NULL;
  if (data && fread(data, 1, (size_t)*bytes, in) != (size_t)*bytes) {
    free(data);
    data = NULL;
  }
  fclose(in);
  return data;
}

/* Publishes `sample` of `type` on ROS 2 topic `topic` once a reader matched,
 * and waits until every matched reader acknowledged it. */
static int publish(const char* domain, const char* topic, const dds_topic_descriptor_t* type, const void* sample,
                   const char* what, const char* seconds) {
  const dds_entity_t participant = dds_create_participant((dds_domainid_t)atoi(domain), NULL, NULL);
  if (participant < 0) return fail("dds_create_participant failed");
  char topic_name[512];
  snprintf(topic_name, sizeof topic_name, "rt%s%s", topic[0] == '/' ? "" : "/", topic);
  const dds_entity_t t = dds_create_topic(participant, type, topic_name, NULL, NULL);
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(10));
  dds_qset_durability(qos, DDS_DURABILITY_TRANSIENT_LOCAL);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 1);
  const dds_entity_t writer = dds_create_writer(participant, t, qos, NULL);
  dds_delete_qos(qos);
  if (t < 0 || writer < 0) return fail("cannot create the writer");
  dds_set_status_mask(writer, DDS_PUBLICATION_MATCHED_STATUS);

  const dds_time_t deadline = dds_time() + DDS_SECS(atoi(seconds));
  dds_publication_matched_status_t matched = {0};
  while (matched.current_count == 0 && dds_time() < deadline) {
    dds_get_publication_matched_status(writer, &matched);
    if (matched.current_count == 0) dds_sleepfor(DDS_MSECS(50));
  }
  int code = 1;
  if (matched.current_count > 0 && dds_write(writer, sample) == DDS_RETCODE_OK &&
      dds_wait_for_acks(writer, deadline - dds_time()) == DDS_RETCODE_OK) {
    printf("published %s on %s; %d readers acknowledged\n", what, topic_name, (int)matched.current_count);
    code = 0;
  } else {
    fprintf(stderr, "cyclone_cloud_publisher: no reader acknowledged %s within %s s\n", topic_name, seconds);
  }
  dds_delete(participant);
  return code;
}

/* An Octomap of the tree data in `path`: `layout` octomap-binary@RES or octomap-full@RES. */
static int publish_octomap(char** argv) {
  const char* layout = argv[4];
  const int binary = strncmp(layout, "octomap-binary@", 15) == 0;
  if (!binary && strncmp(layout, "octomap-full@", 13) != 0) return fail("LAYOUT: octomap-binary@RES or octomap-full@RES");
  long bytes = 0;
  int8_t* data = read_file(argv[3], &bytes);
  if (!data) return fail("cannot read the tree's data");
  octomap_msgs_msg_dds__Octomap_ msg;
  memset(&msg, 0, sizeof msg);
  msg.header.frame_id = argv[5];
  msg.header.stamp.sec = 1700000000;
  msg.binary = binary;
  msg.id = "OcTree";
  msg.resolution = atof(strchr(layout, '@') + 1);
  msg.data._buffer = data;
  msg.data._length = msg.data._maximum = (uint32_t)bytes;
  char what[128];
  snprintf(what, sizeof what, "an Octomap (%s, %ld bytes)", binary ? "binary" : "full", bytes);
  const int code = publish(argv[1], argv[2], &octomap_msgs_msg_dds__Octomap__desc, &msg, what, argv[6]);
  free(data);
  return code;
}

int main(int argc, char** argv) {
  if (argc != 7) return fail("usage: DOMAIN TOPIC POINTS LAYOUT FRAME SECONDS");
  if (strncmp(argv[4], "octomap", 7) == 0) return publish_octomap(argv);
  const int wide = strcmp(argv[4], "xyz64") == 0;
  if (!wide && strcmp(argv[4], "xyzi32") != 0) return fail("LAYOUT must be xyzi32 or xyz64");
  long bytes = 0;
  float* xyz = read_file(argv[3], &bytes);
  if (!xyz) return fail("cannot read POINTS");
  const uint32_t n = (uint32_t)(bytes / 12);

  sensor_msgs_msg_dds__PointCloud2_ msg;
  memset(&msg, 0, sizeof msg);
  msg.header.frame_id = argv[5];
  msg.header.stamp.sec = 1700000000;
  msg.is_bigendian = false;
  msg.is_dense = true;
  /* xyz64: float64 (datatype 8) x, y, z and padding, in two rows (the first
   * n / 2 points, then the rest), each padded by 16 bytes. xyzi32: float32
   * (7) x, y, z and intensity in one row. */
  static const char* const names[] = {"x", "y", "z", "intensity"};
  const uint8_t datatype = wide ? 8 : 7;
  const uint32_t coordinate = wide ? 8 : 4, fields = wide ? 3 : 4;
  msg.fields._buffer = calloc(fields, sizeof(sensor_msgs_msg_dds__PointField_));
  msg.fields._release = true;
  msg.fields._length = msg.fields._maximum = fields;
  for (uint32_t k = 0; k < fields; ++k) put_field(&msg.fields._buffer[k], names[k], k * coordinate, datatype);
  msg.point_step = wide ? 32 : 16;
  msg.height = wide ? 2 : 1;
  msg.width = wide ? (n + 1) / 2 : n;
  msg.row_step = msg.width * msg.point_step + (wide ? 16 : 0);
  const size_t size = (size_t)msg.height * msg.row_step;
  uint8_t* data = calloc(size, 1);
  for (uint32_t i = 0; i < n; ++i) {
    const uint32_t row = wide ? i / msg.width : 0, col = wide ? i % msg.width : i;
    uint8_t* p = data + (size_t)row * msg.row_step + (size_t)col * msg.point_step;
    if (wide) {
      for (int k = 0; k < 3; ++k) {
        const double v = xyz[3 * i + k];
        memcpy(p + 8 * k, &v, 8);
      }
    } else {
      memcpy(p, &xyz[3 * i], 12);
      const float intensity = (float)(i % 256);
      memcpy(p + 12, &intensity, 4);
    }
  }
  /* An odd count leaves the organised cloud's last point a hole, as a depth camera's. */
  if (wide && n % 2 == 1) {
    const double nan = strtod("nan", NULL);
    uint8_t* p = data + (size_t)msg.row_step + (size_t)(msg.width - 1) * msg.point_step;
    for (int k = 0; k < 3; ++k) memcpy(p + 8 * k, &nan, 8);
  }
  msg.data._buffer = data;
  msg.data._length = msg.data._maximum = (uint32_t)size;

  char what[128];
  snprintf(what, sizeof what, "%u points (%zu bytes, %s)", n, size, argv[4]);
  const int code = publish(argv[1], argv[2], &sensor_msgs_msg_dds__PointCloud2__desc, &msg, what, argv[6]);
  for (uint32_t k = 0; k < fields; ++k) free(msg.fields._buffer[k].name);
  free(msg.fields._buffer);
  free(data);
  free(xyz);
  return code;
}
