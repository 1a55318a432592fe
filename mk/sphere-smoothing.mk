# sphere smoothing (paper 000 §4.1(1), fig. 11-12): an R500 sphere traced in scanning-line mode with
# pick feed 1.0 mm by a virtual stylus at the cutting point of the φ25 cylindrical non-rotating tool
# (r = 12.5). tool-attitude (tilt −5° toward the feed) and post-6axis carry cl.csv on.
DEMOS += sphere-smoothing
FILTERS += stylus-trace
SPHERE_SMOOTHING := $(OUT)/sphere-smoothing
SPHERE_SMOOTHING_STYLUS ?= 12.5
SPHERE_SMOOTHING_PICK ?= 1.0
SPHERE_SMOOTHING_REGION ?= -50,50,-50,50
SPHERE_SMOOTHING_CHORD_TOL ?= 0.001

.PHONY: demo-sphere-smoothing
demo-sphere-smoothing: $(SPHERE_SMOOTHING)/cl.csv

$(SPHERE_SMOOTHING)/model.json: data/stylus-trace/sphere-smoothing.json | $(SPHERE_SMOOTHING)/
	cp $< $@

$(SPHERE_SMOOTHING)/cl.csv $(SPHERE_SMOOTHING)/cl.svg $(SPHERE_SMOOTHING)/cl.json &: $(SPHERE_SMOOTHING)/model.json $(RELEASE)/stylus-trace
	$(RELEASE)/stylus-trace $< --mode scan -r $(SPHERE_SMOOTHING_STYLUS) --pick $(SPHERE_SMOOTHING_PICK) \
	  --region=$(SPHERE_SMOOTHING_REGION) --chord-tol $(SPHERE_SMOOTHING_CHORD_TOL) \
	  --svg $(SPHERE_SMOOTHING)/cl.svg --report $(SPHERE_SMOOTHING)/cl.json -o $(SPHERE_SMOOTHING)/cl.csv
