"""pmr light field: render the scene as a Looking Glass quilt / panel image with pmr.

The add-on exports the visible scene with Blender's glTF exporter, runs the pmr command line
renderer on it in a subprocess and loads the quilt it writes. See README.md beside this file.
"""

bl_info = {
    "name": "pmr Light Field",
    "author": "pmr authors",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "Properties > Render > pmr Light Field",
    "description": "Render light-field quilts and Looking Glass panel images with pmr",
    "category": "Render",
}

# Reloading the add-on from Blender's preferences re-imports the package; re-import the modules too.
if "bpy" in locals():
    import importlib

    for _module in (command, export, runner, properties, operators, ui):  # noqa: F821
        importlib.reload(_module)
else:
    from . import command, export, runner, properties, operators, ui

import bpy  # noqa: E402

_classes = properties.CLASSES + operators.CLASSES + ui.CLASSES


def register():
    for cls in _classes:
        bpy.utils.register_class(cls)
    properties.attach()


def unregister():
    properties.detach()
    for cls in reversed(_classes):
        bpy.utils.unregister_class(cls)
