"""SLAM methods: hector_mapping, slam_gmapping and graph SLAM (each a subpackage)."""
