from setuptools import setup
from catkin_pkg.python_setup import generate_distutils_setup

setup(**generate_distutils_setup(
    packages=["gui", "gui.core", "gui.core.kautham", "gui.core.translate", "gui.planning",
              "gui.ros", "gui.tools", "gui.window"],
    package_dir={"": "src"}))
