import os
from glob import glob

from setuptools import find_packages, setup

package_name = 'py_pulse'

setup(
    name=package_name,
    version='0.0.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages',
            ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        (os.path.join('share', package_name, 'launch'),
            glob(os.path.join('launch', '*launch.[pxy][yma]*'))),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='learner',
    maintainer_email='learner@example.com',
    description='Two nodes and a launch file',
    license='Apache-2.0',
    tests_require=['pytest'],
    entry_points={
        'console_scripts': [
            'heartbeat = py_pulse.heartbeat:main',
            'relay = py_pulse.relay:main',
        ],
    },
)
