# Run by `freecadcmd` (FreeCAD's Python): a box, a Path Job with the default
# tool controller, a profile around the box, posted with the post processor
# "ncpp" found in the macro directory, once with NCPP_POST_ARGS (the Job's
# post processor arguments) into NCPP_OUT, once with NCPP_PLAIN_ARGS into
# NCPP_PLAIN_OUT.  FreeCAD 0.20 posts through the module's export(); 1.x as its
# Post Process command does (PostProcessorFactory: the class Ncpp), and checks
# the legacy script API (WrapperPost) gives the same program.
import os
import sys
import traceback

try:
    import FreeCAD

    doc = FreeCAD.newDocument("ncpp_test")
    box = doc.addObject("Part::Box", "Box")
    box.Length, box.Width, box.Height = 60.0, 40.0, 10.0
    doc.recompute()

    try:  # FreeCAD 1.x: the CAM workbench's Python package is Path
        from Path import Preferences as PathPreferences
        from Path.Main import Job as PathJob
        from Path.Op import Profile as PathProfile
        from Path.Post.Processor import PostProcessorFactory, WrapperPost
    except ImportError:  # FreeCAD 0.19-0.21: PathScripts; Path is only the C++ module
        from PathScripts import PathJob, PathPostProcessor, PathPreferences, PathProfile

        PostProcessorFactory = None

    job = PathJob.Create("Job", [box], None)
    tool = job.Tools.Group[0]
    tool.HorizFeed, tool.VertFeed, tool.SpindleSpeed = "600 mm/min", "200 mm/min", 8000.0
    profile = PathProfile.Create("Profile")
    doc.recompute()
    assert "ncpp" in PathPreferences.allAvailablePostProcessors(), PathPreferences.searchPathsPost()
    print("NCPP_COMMANDS", sum(len(op.Path.Commands) for op in job.Operations.Group))

    def post(filename, argstring):
        """Post the job as FreeCAD's Post Process command does."""
        if PostProcessorFactory is None:  # 0.20: module export() writes the file
            objects = [job.Tools.Group[0]] + [op for op in job.Operations.Group]
            PathPostProcessor.PostProcessor.load("ncpp").export(objects, filename, argstring)
            return
        job.PostProcessor, job.PostProcessorArgs = "ncpp", argstring
        unbound = PostProcessorFactory.get_post_processor(None, "ncpp")  # as the Preferences dialog asks
        assert "--machine" in unbound.tooltipArgs and unbound.units == "Metric", (unbound.tooltipArgs, unbound.units)
        processor = PostProcessorFactory.get_post_processor(job, "ncpp")
        print("NCPP_PROCESSOR", type(processor).__name__)
        sections = processor.export()  # [(subpart, gcode)], one "allitems" unless split
        assert [name for name, _ in sections] == ["allitems"], sections
        # What 1.x does with a script that has no class: the legacy export(objects, "-", args).
        script = os.path.join(PathPreferences.macroFilePath(), "ncpp_post.py")
        legacy = WrapperPost(job, script).export()
        untimed = [[ln for ln in gcode.splitlines() if not ln.startswith("(Output Time:")] for _, gcode in sections + legacy]
        print("NCPP_LEGACY_SAME", untimed[0] == untimed[1])
        with open(filename, "w", encoding="latin-1", newline="") as f:
            f.write(sections[0][1])

    post(os.environ["NCPP_OUT"], os.environ["NCPP_POST_ARGS"])
    post(os.environ["NCPP_PLAIN_OUT"], os.environ["NCPP_PLAIN_ARGS"])
    if os.environ.get("NCPP_BASE_OUT"):  # through another of FreeCAD's posts (--base)
        post(os.environ["NCPP_BASE_OUT"], os.environ["NCPP_BASE_ARGS"])
    print("NCPP_POSTED", FreeCAD.Version()[0] + "." + FreeCAD.Version()[1] + "." + FreeCAD.Version()[2])
except Exception:
    traceback.print_exc()
    print("NCPP_FAILED")
sys.stdout.flush()
os._exit(0)
