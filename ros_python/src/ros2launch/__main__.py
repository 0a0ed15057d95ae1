"""``python -m ros2launch PACKAGE FILE [name:=value ...]`` is ``ros2 launch``.

Absolute imports only: the classroom's sandbox also runs this file by path.
"""

import sys

from ros2launch.command import main

if __name__ == "__main__":
    sys.exit(main())
