// ConnectionGate's address parsing and binding (its floods are navd_soak_test's).

#include "connection_gate.h"

#include <stdexcept>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace egress::navd {
namespace {

using ::testing::HasSubstr;

TEST(ParseListenAddressTest, ReadsHostAndPortAndRefusesBadPorts) {
  EXPECT_EQ(ParseListenAddress("127.0.0.1:50051").port, 50051);
  EXPECT_EQ(ParseListenAddress("127.0.0.1:0").port, 0);
  EXPECT_EQ(ParseListenAddress("[::1]:65535").host, "::1");
  for (const char* bad : {"127.0.0.1:65536", "127.0.0.1:99999", "127.0.0.1:-1",
                          "127.0.0.1:", "127.0.0.1", "127.0.0.1:5x", ":50051"}) {
    EXPECT_THROW(ParseListenAddress(bad), std::invalid_argument) << bad;
  }
  try {
    ParseListenAddress("localhost:99999");
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("'99999' is not a number in 0..65535"));
  }
}

TEST(ConnectionGateTest, BindsAFreePortAndNamesAnAddressInUse) {
  ConnectionGate first("127.0.0.1:0", 4);
  EXPECT_GT(first.port(), 0);
  try {
    ConnectionGate second("127.0.0.1:" + std::to_string(first.port()), 4);
    FAIL() << "bound a port already listened on";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("cannot listen on '127.0.0.1:" + std::to_string(first.port())));
  }
  EXPECT_THROW(ConnectionGate("127.0.0.1:0", 0), std::invalid_argument);
}

}  // namespace
}  // namespace egress::navd
