"""The add-on's settings: per scene (scene.pmr_lightfield) and global (add-on preferences)."""

import bpy
from bpy.props import (BoolProperty, EnumProperty, IntProperty, PointerProperty, StringProperty)

# pmr render --preset help; kept here so the panel works before pmr is found.
PRESETS = [
    ("lg-portrait", "Looking Glass Portrait", "1536x2048, 48 views of 420x560"),
    ("lg-go", "Looking Glass Go", "1440x2560, 66 views of 372x682"),
    ("lg-16", "Looking Glass 16\" landscape", "3840x2160, 49 views of 857x857"),
    ("lg-16-portrait", "Looking Glass 16\" portrait", "2160x3840, 66 views of 545x1000"),
    ("lg-32", "Looking Glass 32\" landscape", "7680x4320, 49 views of 1170x1170"),
    ("lg-32-portrait", "Looking Glass 32\" portrait", "4320x7680, 66 views of 744x1364"),
    ("lg-16-gen2", "Looking Glass 16\" Gen2", "3840x2160, 45 views of 819x455"),
    ("lg-32-gen2", "Looking Glass 32\" Gen2", "7680x4320, 45 views of 1638x910"),
    ("paper-8k", "PMR paper 8K panel", "7680x4320, 96 views of 1024x512"),
]


def addon_prefs(context):
    """The add-on's preferences (the package name is the add-on's module name)."""
    return context.preferences.addons[__package__].preferences


class PmrLightfieldPreferences(bpy.types.AddonPreferences):
    bl_idname = __package__

    pmr_path: StringProperty(
        name="pmr executable",
        description="Path of the pmr program; 'pmr' looks it up on PATH",
        subtype='FILE_PATH',
        default="pmr",
    )
    keep_export: BoolProperty(
        name="Keep exported glTF",
        description="Leave the exported scene in the output folder (pmr_scene/) instead of a temporary "
                    "folder, to rerun pmr by hand",
        default=False,
    )

    def draw(self, context):
        self.layout.prop(self, "pmr_path")
        self.layout.prop(self, "keep_export")


class PmrLightfieldSettings(bpy.types.PropertyGroup):
    display_source: EnumProperty(
        name="Display",
        items=[("PRESET", "Preset", "One of pmr's display presets (--preset)"),
               ("CONFIG", "Calibration", "A Looking Glass panel's own visual.json (--display-config)")],
        default="PRESET",
    )
    preset: EnumProperty(name="Preset", items=PRESETS, default="lg-portrait")
    display_config: StringProperty(name="Calibration", subtype='FILE_PATH',
                                   description="The panel's visual.json")
    views: IntProperty(name="Views", min=0, max=1024, default=0,
                       description="Number of views (--views); 0: the display's recommended count")
    view_width: IntProperty(name="View width", min=0, max=8192, default=0,
                            description="View raster width in pixels; 0: the display's")
    view_height: IntProperty(name="View height", min=0, max=8192, default=0,
                             description="View raster height in pixels; 0: the display's")
    sampling: EnumProperty(
        name="Sampling",
        items=[("DEFAULT", "Display default", "pmr's default for the display"),
               ("view", "View", "Render every view on its grid (--sampling view)"),
               ("subpixel", "Subpixel", "Rasterize every display subpixel at its own sample "
                                        "(--sampling subpixel; the encoded image only)")],
        default="DEFAULT",
    )
    samples: EnumProperty(
        name="Samples",
        items=[("1", "1", "Point sampled"), ("4", "4", "4 samples per pixel"),
               ("8", "8", "8 samples per pixel"), ("16", "16", "16 samples per pixel")],
        default="4",
        description="Antialiasing samples per pixel (--samples)",
    )
    texture_filter: EnumProperty(
        name="Texture filter",
        items=[("trilinear", "Trilinear", "Mip-mapped textures and specular antialiasing"),
               ("bilinear", "Bilinear", "Full-resolution textures only")],
        default="trilinear",
    )
    environment: EnumProperty(
        name="Environment",
        items=[("WORLD", "From World", "The world's Environment Texture image, or its background "
                                       "colour, or nothing when the world is black"),
               ("STUDIO", "pmr studio", "pmr's built-in studio room"),
               ("NONE", "None", "Only the scene's lights")],
        default="WORLD",
    )
    shadow_catcher: BoolProperty(
        name="Shadow catcher", default=False,
        description="A shadow catcher under the scene at its lowest point, showing only the shadows "
                    "cast on it, as Blender's shadow catcher does (--ground shadow)")
    output_dir: StringProperty(name="Output folder", subtype='DIR_PATH', default="//pmr/")
    name: StringProperty(name="File name", default="frame_####",
                         description="File stem (--name); #### is the frame number")
    mode: EnumProperty(
        name="Render",
        items=[("STILL", "Still", "The current frame"),
               ("SEQUENCE", "Sequence", "Every frame of the frame range")],
        default="STILL",
    )
    use_scene_range: BoolProperty(name="Scene frame range", default=True,
                                  description="Render the scene's start to end frame")
    frame_start: IntProperty(name="Start", min=0, default=1)
    frame_end: IntProperty(name="End", min=0, default=250)
    write: EnumProperty(
        name="Write",
        items=[("QUILT", "Quilt", "The views as a Looking Glass quilt EXR"),
               ("ENCODED", "Panel image", "The encoded panel image EXR"),
               ("BOTH", "Both", "Quilt and panel image")],
        default="QUILT",
    )
    extra_args: StringProperty(name="Extra options",
                               description="More pmr render options, as on the command line")


def attach():
    bpy.types.Scene.pmr_lightfield = PointerProperty(type=PmrLightfieldSettings)


def detach():
    del bpy.types.Scene.pmr_lightfield


CLASSES = [PmrLightfieldPreferences, PmrLightfieldSettings]
