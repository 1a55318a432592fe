# globe (paper 002): a sphere on the A/C table measured on the machine by a simulated laser sensor —
# a 3-axis raster, its rough Delaunay surface, a 5-axis plan along the surface normals (posted to NC),
# the 5-axis measurement — and fitted: the workpiece frame for post-6axis, with the 3-axis and
# 5-axis fit errors against the true sphere side by side (summary.txt). Then Honshu's coastline
# (Natural Earth) mapped by longitude and latitude onto the fitted sphere, tool axis along the
# normal, offset for a φ0.2 mm flat end mill in the plane normal to the axis (offset --3d, which
# refuses a path that would cut into a coastline: with R 1.5, or with Hokkaido and Kyushu beside
# Honshu, it does), and posted for the A/C table machine in the measured workpiece frame (globe.ngc).
DEMOS += globe
FILTERS += surf-probe-fit offset post-6axis
GLOBE := $(OUT)/globe
GLOBE_TRUE ?= data/surf-probe-fit/globe-true.json
GLOBE_MACHINE ?= data/post-6axis/paper002-ac.json
GLOBE_REGION ?= -28,34,-31,29
GLOBE_STEP ?= 2
GLOBE_Z ?= 115.5
GLOBE_EVERY ?= 5
GLOBE_STANDOFF ?= 50
GLOBE_SEED ?= 1
GLOBE_COAST ?= data/surf-probe-fit/honshu-coastline.json
GLOBE_LON0 ?= 138
GLOBE_DEPTH ?= 0.2
GLOBE_TOOL_R ?= 0.1
GLOBE_FEED ?= 300
# The cutting job: stock round the globe, heights, the φ0.2 flat end mill (data/jobs/README.md).
GLOBE_SETUP ?= data/jobs/globe.json

.PHONY: demo-globe
demo-globe: $(GLOBE)/summary.txt $(GLOBE)/plan.ngc $(GLOBE)/globe.ngc

$(GLOBE)/raster.csv: mk/globe.mk $(RELEASE)/surf-probe-fit | $(GLOBE)/
	$(RELEASE)/surf-probe-fit raster --region=$(GLOBE_REGION) --step $(GLOBE_STEP) --z $(GLOBE_Z) -o $@

$(GLOBE)/raster-records.csv: $(GLOBE)/raster.csv $(GLOBE_TRUE) $(RELEASE)/surf-probe-fit
	$(RELEASE)/surf-probe-fit simulate $< --shape $(GLOBE_TRUE) --standoff $(GLOBE_STANDOFF) --seed $(GLOBE_SEED) --report $(GLOBE)/raster-records.json -o $@

$(GLOBE)/raster-points.csv: $(GLOBE)/raster-records.csv $(RELEASE)/surf-probe-fit
	$(RELEASE)/surf-probe-fit points $< -o $@

$(GLOBE)/fit-3axis.json: $(GLOBE)/raster-points.csv $(GLOBE_TRUE) $(RELEASE)/surf-probe-fit
	$(RELEASE)/surf-probe-fit fit $< --truth $(GLOBE_TRUE) --report $(GLOBE)/fit-3axis-report.json -o $@

$(GLOBE)/plan.csv: $(GLOBE)/raster-points.csv $(RELEASE)/surf-probe-fit
	$(RELEASE)/surf-probe-fit plan $< --every $(GLOBE_EVERY) --standoff $(GLOBE_STANDOFF) --report $(GLOBE)/plan.json -o $@

$(GLOBE)/plan.ngc: $(GLOBE)/plan.csv $(GLOBE_MACHINE) $(RELEASE)/post-6axis
	$(RELEASE)/post-6axis $< --machine $(GLOBE_MACHINE) --frame data/surf-probe-fit/table-frame.json --feed 2000 --report $(GLOBE)/plan-post.json -o $@

$(GLOBE)/records-5axis.csv: $(GLOBE)/plan.csv $(GLOBE_TRUE) $(GLOBE_MACHINE) $(RELEASE)/surf-probe-fit
	$(RELEASE)/surf-probe-fit simulate $< --machine $(GLOBE_MACHINE) --shape $(GLOBE_TRUE) --standoff $(GLOBE_STANDOFF) --seed $(GLOBE_SEED) --report $(GLOBE)/records-5axis.json -o $@

$(GLOBE)/frame.json: $(GLOBE)/records-5axis.csv $(GLOBE_TRUE) $(GLOBE_MACHINE) $(RELEASE)/surf-probe-fit
	$(RELEASE)/surf-probe-fit fit $< --machine $(GLOBE_MACHINE) --truth $(GLOBE_TRUE) --report $(GLOBE)/frame-report.json -o $@

$(GLOBE)/summary.txt: $(GLOBE)/fit-3axis.json $(GLOBE)/frame.json
	for m in 3axis 5axis; do \
	  r=$(GLOBE)/fit-3axis-report.json; [ $$m = 5axis ] && r=$(GLOBE)/frame-report.json; \
	  printf '%s fit: ' $$m; grep -E '"(points|rms_mm|origin_error_mm|radius_error_mm)"' $$r | tr -d ' \n'; echo; \
	done > $@
	cat $@

$(GLOBE)/coastline.csv: $(GLOBE_COAST) $(GLOBE)/frame.json $(RELEASE)/surf-probe-fit
	$(RELEASE)/surf-probe-fit map $< --frame $(GLOBE)/frame.json --lon0 $(GLOBE_LON0) --depth $(GLOBE_DEPTH) -o $@

$(GLOBE)/coastline-offset.csv: $(GLOBE)/coastline.csv $(RELEASE)/offset
	$(RELEASE)/offset $< --3d --radius $(GLOBE_TOOL_R) --side left --report $(GLOBE)/coastline-offset.json -o $@

$(GLOBE)/globe.ngc $(GLOBE)/globe.json &: $(GLOBE)/coastline-offset.csv $(GLOBE)/frame.json $(GLOBE_MACHINE) $(GLOBE_SETUP) $(RELEASE)/post-6axis
	$(RELEASE)/post-6axis $< --machine $(GLOBE_MACHINE) --frame $(GLOBE)/frame.json --setup $(GLOBE_SETUP) --feed $(GLOBE_FEED) --report $(GLOBE)/globe.json -o $(GLOBE)/globe.ngc
