# Run by `freecadcmd` (FreeCAD's Python): a box, a Path Job with the default
# tool controller, a profile around the box, posted with the post processor
# "ncpp" found in the macro directory, once with NCPP_POST_ARGS (the Job's
# post processor arguments) into NCPP_OUT, once with NCPP_PLAIN_ARGS into
# NCPP_PLAIN_OUT.
import os
import sys
import traceback

try:
    import FreeCAD

    doc = FreeCAD.newDocument("ncpp_test")
    box = doc.addObject("Part::Box", "Box")
    box.Length, box.Width, box.Height = 60.0, 40.0, 10.0
    doc.recompute()

    from PathScripts import PathJob, PathPostProcessor, PathPreferences, PathProfile

    job = PathJob.Create("Job", [box], None)
    tool = job.Tools.Group[0]
    tool.HorizFeed, tool.VertFeed, tool.SpindleSpeed = "600 mm/min", "200 mm/min", 8000.0
    profile = PathProfile.Create("Profile")
    doc.recompute()
    assert "ncpp" in PathPreferences.allAvailablePostProcessors(), PathPreferences.searchPathsPost()
    post = PathPostProcessor.PostProcessor.load("ncpp")
    objects = [job.Tools.Group[0]] + [op for op in job.Operations.Group]
    print("NCPP_COMMANDS", sum(len(op.Path.Commands) for op in job.Operations.Group))
    post.export(objects, os.environ["NCPP_OUT"], os.environ["NCPP_POST_ARGS"])
    post.export(objects, os.environ["NCPP_PLAIN_OUT"], os.environ["NCPP_PLAIN_ARGS"])
    print("NCPP_POSTED", FreeCAD.Version()[0] + "." + FreeCAD.Version()[1] + "." + FreeCAD.Version()[2])
except Exception:
    traceback.print_exc()
    print("NCPP_FAILED")
sys.stdout.flush()
os._exit(0)
