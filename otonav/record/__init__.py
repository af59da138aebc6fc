"""Recording: MCAP (ROS 2 CDR) writing, reading, info and salvage."""
