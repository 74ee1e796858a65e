/* A ROS 2 peer that no one here wrote the middleware of: Cyclone DDS's C API, with the types
 * idlc generated from the same ROS 2 message IDL (in ROS 2's DDS naming). It subscribes to the
 * robot's scan and odometry as a ROS 2 node with the sensor-data QoS would, prints the fields it
 * received, then publishes a Twist on cmd_vel for a few seconds.
 *   cyclone_peer DOMAIN    exit 0: both received and the Twist sent; 2: nothing within 30 s */
#include <stdio.h>
#include <stdlib.h>

#include <dds/dds.h>

#include "geometry_msgs/msg/Twist.h"
#include "nav_msgs/msg/Odometry.h"
#include "sensor_msgs/msg/LaserScan.h"

static dds_qos_t* SensorQos(void) {
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_BEST_EFFORT, 0);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 5);
  return qos;
}

int main(int argc, char** argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: cyclone_peer DOMAIN\n");
    return 1;
  }
  const dds_domainid_t domain = (dds_domainid_t)atoi(argv[1]);
  const dds_entity_t participant = dds_create_participant(domain, NULL, NULL);
  if (participant < 0) {
    fprintf(stderr, "cyclone: participant: %s\n", dds_strretcode(-participant));
    return 1;
  }
  dds_qos_t* sensor = SensorQos();
  const dds_entity_t scan_topic = dds_create_topic(
      participant, &sensor_msgs_msg_dds__LaserScan__desc, "rt/scan", NULL, NULL);
  const dds_entity_t odom_topic = dds_create_topic(
      participant, &nav_msgs_msg_dds__Odometry__desc, "rt/omni_base_controller/wheel_odom", NULL,
      NULL);
  const dds_entity_t twist_topic = dds_create_topic(
      participant, &geometry_msgs_msg_dds__Twist__desc, "rt/omni_base_controller/cmd_vel", NULL,
      NULL);
  const dds_entity_t scan_reader = dds_create_reader(participant, scan_topic, sensor, NULL);
  const dds_entity_t odom_reader = dds_create_reader(participant, odom_topic, sensor, NULL);
  dds_qos_t* reliable = dds_create_qos();
  dds_qset_reliability(reliable, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_history(reliable, DDS_HISTORY_KEEP_LAST, 10);
  const dds_entity_t twist_writer = dds_create_writer(participant, twist_topic, reliable, NULL);
  if (scan_reader < 0 || odom_reader < 0 || twist_writer < 0) {
    fprintf(stderr, "cyclone: endpoints could not be created\n");
    return 1;
  }
  int have_scan = 0, have_odom = 0;
  for (int i = 0; i < 3000 && !(have_scan && have_odom); ++i) {
    void* samples[1] = {NULL};
    dds_sample_info_t infos[1];
    if (!have_scan && dds_take(scan_reader, samples, infos, 1, 1) > 0 && infos[0].valid_data) {
      const sensor_msgs_msg_dds__LaserScan_* s = samples[0];
      printf("scan frame_id=%s stamp=%d.%09u n=%u r7=%.4f angle_min=%.4f range_max=%.2f\n",
             s->header.frame_id, s->header.stamp.sec, s->header.stamp.nanosec,
             s->ranges._length, s->ranges._length > 7 ? s->ranges._buffer[7] : -1.0f,
             s->angle_min, s->range_max);
      have_scan = 1;
    }
    if (samples[0] != NULL) dds_return_loan(scan_reader, samples, 1);
    samples[0] = NULL;
    if (!have_odom && dds_take(odom_reader, samples, infos, 1, 1) > 0 && infos[0].valid_data) {
      const nav_msgs_msg_dds__Odometry_* o = samples[0];
      printf("odom frame_id=%s child=%s x=%.4f y=%.4f qz=%.6f qw=%.6f vx=%.4f wz=%.4f cov35=%.4f\n",
             o->header.frame_id, o->child_frame_id, o->pose.pose.position.x,
             o->pose.pose.position.y, o->pose.pose.orientation.z, o->pose.pose.orientation.w,
             o->twist.twist.linear.x, o->twist.twist.angular.z, o->pose.covariance[35]);
      have_odom = 1;
    }
    if (samples[0] != NULL) dds_return_loan(odom_reader, samples, 1);
    fflush(stdout);
    dds_sleepfor(DDS_MSECS(10));
  }
  if (!(have_scan && have_odom)) {
    printf("cyclone: nothing within 30 s: scan %d, odometry %d\n", have_scan, have_odom);
    return 2;
  }
  geometry_msgs_msg_dds__Twist_ twist = {0};
  twist.linear.x = 0.25;
  twist.linear.y = -0.05;
  twist.angular.z = 0.5;
  for (int i = 0; i < 60; ++i) {
    dds_write(twist_writer, &twist);
    dds_sleepfor(DDS_MSECS(50));
  }
  printf("twist sent\n");
  fflush(stdout);
  dds_delete(participant);
  dds_delete_qos(sensor);
  dds_delete_qos(reliable);
  return 0;
}
