# concave remainder, six-axis (paper 000 §3.2(2), §4.2(2), fig. 7-10, 18): tool-attitude puts the
# flat-type non-rotating tool's tip P2 on the two-surface trace, starts from the bisector of both
# normals and turns the axis until the control stylus at P1 touches the free-form surface, so that
# flank lies on it (the model is asked at every row); the tool's included angle is 65°, about 5°
# under the corner's smallest. post-6axis writes six-axis NC with M19 spindle orientation. This
# file sorts before mk/concave-remainder.mk, so it names the directory itself.
FILTERS += tool-attitude post-6axis
CONCAVE_REMAINDER_6AXIS := $(OUT)/concave-remainder
CONCAVE_REMAINDER_TOOL ?= data/tool-attitude/flat-type.json
CONCAVE_REMAINDER_CONTROL ?= p1
CONCAVE_REMAINDER_MACHINE ?= data/post-6axis/paper000-sixaxis-m19.json
CONCAVE_REMAINDER_FEED ?= 500
# Read-back tolerance of the NC (mm): the issue asks for the demo parts within 1 µm.
CONCAVE_REMAINDER_NC_TOL ?= 0.001
# The job: stock round the concave line, heights over the R25 sphere (data/jobs/README.md).
CONCAVE_REMAINDER_SETUP ?= data/jobs/concave-remainder.json

demo-concave-remainder: $(CONCAVE_REMAINDER_6AXIS)/tool.csv $(CONCAVE_REMAINDER_6AXIS)/part.ngc

$(CONCAVE_REMAINDER_6AXIS)/tool.csv $(CONCAVE_REMAINDER_6AXIS)/tool.json &: $(CONCAVE_REMAINDER_6AXIS)/cl.csv \
  $(CONCAVE_REMAINDER_6AXIS)/model.json $(CONCAVE_REMAINDER_TOOL) $(RELEASE)/tool-attitude
	$(RELEASE)/tool-attitude $< --tool $(CONCAVE_REMAINDER_TOOL) --control $(CONCAVE_REMAINDER_CONTROL) \
	  --model $(CONCAVE_REMAINDER_6AXIS)/model.json \
	  --report $(CONCAVE_REMAINDER_6AXIS)/tool.json -o $(CONCAVE_REMAINDER_6AXIS)/tool.csv

$(CONCAVE_REMAINDER_6AXIS)/part.ngc $(CONCAVE_REMAINDER_6AXIS)/part.json &: $(CONCAVE_REMAINDER_6AXIS)/tool.csv \
  $(CONCAVE_REMAINDER_MACHINE) $(CONCAVE_REMAINDER_SETUP) $(RELEASE)/post-6axis
	$(RELEASE)/post-6axis $< --machine $(CONCAVE_REMAINDER_MACHINE) --setup $(CONCAVE_REMAINDER_SETUP) --feed $(CONCAVE_REMAINDER_FEED) --tol $(CONCAVE_REMAINDER_NC_TOL) \
	  --report $(CONCAVE_REMAINDER_6AXIS)/part.json -o $(CONCAVE_REMAINDER_6AXIS)/part.ngc
