"""Cycles set up as the Blender scripts of tests/blender compare it with pmr: CPU, no denoiser, the image at
100% of its resolution through the Standard view transform (sRGB, no look, exposure 0, gamma 1)."""


def plain_cycles(scene, samples):
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False
    scene.render.resolution_percentage = 100
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
