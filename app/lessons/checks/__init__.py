"""Check kinds, one module each; importing the package registers them all (see
``app.lessons.registry`` for how to add one)."""

from app.lessons.registry import import_all

import_all(__name__, __path__)
