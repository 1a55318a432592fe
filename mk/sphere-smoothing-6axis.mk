# sphere smoothing, six-axis (paper 000 §3.2(1), §4.2(1), fig. 6, 15): tool-attitude turns the stylus
# trace into tool tip, tool axis and spindle orientation of the φ25 cylindrical non-rotating tool
# tilted −5° toward the feed (R' = 143 mm by eq. 1), the whole tool body checked against the model;
# post-6axis writes six-axis NC for paper 000's A/C table machine, the edge orientation as a B
# address, the passes linked through the job's safe height and the program checked for collisions. This file sorts before mk/sphere-smoothing.mk, so it names the directory itself.
FILTERS += tool-attitude post-6axis
SPHERE_SMOOTHING_6AXIS := $(OUT)/sphere-smoothing
SPHERE_SMOOTHING_TOOL ?= data/tool-attitude/cylinder-phi25.json
SPHERE_SMOOTHING_TILT ?= -5
SPHERE_SMOOTHING_MACHINE ?= data/post-6axis/paper000-sixaxis-b.json
SPHERE_SMOOTHING_FEED ?= 1000
# Read-back tolerance of the NC (mm): the issue asks for the demo parts within 1 µm.
SPHERE_SMOOTHING_NC_TOL ?= 0.001
# Axis tolerance (degrees): the φ25 rim swings 12.5 mm × this between blocks; at the post's default
# 0.05° that is 10.9 µm into the sphere, which the collision check refuses (tolerance 10 µm).
SPHERE_SMOOTHING_ANGLE_TOL ?= 0.02
# The job: stock over the cap, heights, the tool by reference (data/jobs/README.md).
SPHERE_SMOOTHING_SETUP ?= data/jobs/sphere-smoothing.json

demo-sphere-smoothing: $(SPHERE_SMOOTHING_6AXIS)/tool.csv $(SPHERE_SMOOTHING_6AXIS)/part.ngc

$(SPHERE_SMOOTHING_6AXIS)/tool.csv $(SPHERE_SMOOTHING_6AXIS)/tool.json $(SPHERE_SMOOTHING_6AXIS)/tool.svg &: $(SPHERE_SMOOTHING_6AXIS)/cl.csv \
  $(SPHERE_SMOOTHING_6AXIS)/model.json $(SPHERE_SMOOTHING_TOOL) $(RELEASE)/tool-attitude
	$(RELEASE)/tool-attitude $< --tool $(SPHERE_SMOOTHING_TOOL) --tilt $(SPHERE_SMOOTHING_TILT) \
	  --model $(SPHERE_SMOOTHING_6AXIS)/model.json --svg $(SPHERE_SMOOTHING_6AXIS)/tool.svg \
	  --report $(SPHERE_SMOOTHING_6AXIS)/tool.json -o $(SPHERE_SMOOTHING_6AXIS)/tool.csv

$(SPHERE_SMOOTHING_6AXIS)/part.ngc $(SPHERE_SMOOTHING_6AXIS)/part.json &: $(SPHERE_SMOOTHING_6AXIS)/tool.csv \
  $(SPHERE_SMOOTHING_MACHINE) $(SPHERE_SMOOTHING_SETUP) $(RELEASE)/post-6axis
	$(RELEASE)/post-6axis $< --machine $(SPHERE_SMOOTHING_MACHINE) --setup $(SPHERE_SMOOTHING_SETUP) --feed $(SPHERE_SMOOTHING_FEED) --tol $(SPHERE_SMOOTHING_NC_TOL) \
	  --angle-tol $(SPHERE_SMOOTHING_ANGLE_TOL) \
	  --report $(SPHERE_SMOOTHING_6AXIS)/part.json -o $(SPHERE_SMOOTHING_6AXIS)/part.ngc
