"""The paper's two test scenes, written by scripts/make_paper_scenes: mesh (recipes with their
triangle counts, objects, the scene writer), polygons (scene a), room (scene b) and
make_paper_scenes (the command)."""
