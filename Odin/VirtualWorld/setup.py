from setuptools import setup
from catkin_pkg.python_setup import generate_distutils_setup

setup(**generate_distutils_setup(
    packages=["virtual_world", "virtual_world.core", "virtual_world.ode", "virtual_world.portal"],
    package_dir={"": "src"}))
