"""Readers for Kautham's file formats (problems, .rob/.dh robots, URDF, .cntr controls).

Everything here is ROS-free. Values come out in SI units (m, rad, kg) whatever the file used.
"""
