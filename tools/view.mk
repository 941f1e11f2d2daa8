# SPDX-License-Identifier: BSD-3-Clause
# view.mk - `occmap view` (issue 23): the rendering library, pinned and checked, fetched from the
# npm registry at build time, and the viewer test.
#   make view-assets   $(VIEW_ASSETS)/{three.min.js,OrbitControls.js,view_app.js}: what
#                      tools/view_page.c inlines (the tool finds the folder through
#                      OCC_VIEW_ASSETS, compiled in below, or --assets / $OCCMAP_VIEW_ASSETS)
# three r147 is the last release that ships OrbitControls as a classic script
# (examples/js), so both inline as plain <script> elements without a module loader.
THREE_VERSION := 0.147.0
THREE_INTEGRITY := sha512-LPTOslYQXFkmvceQjFTNnVVli2LaVF6C99Pv34fJypp8NbQLbTlu3KinZ0zURghS5zEehK+VQyvWuPZ/Sm8fzw==
# In build/cache (make clean keeps it): the registry is asked once per machine.
THREE_TGZ := $(BUILD)/cache/npm/three-$(THREE_VERSION).tgz
VIEW_ASSETS := $(BUILD)/view
APT_PKGS += chromium
# nodesource's nodejs carries its own npm; Debian's npm package would conflict with it.
ifeq ($(shell command -v npm 2>/dev/null),)
APT_PKGS += npm
endif

$(BUILD)/relhost/tools/cmd_view.o: EXTRA_CFLAGS += -DOCC_VIEW_ASSETS='"$(abspath $(VIEW_ASSETS))"'

# npm pack fetches the registry's tarball; its sha512 must be the pinned one (the registry's
# dist.integrity for three@0.147.0), else the tarball is deleted and the build stops.
$(THREE_TGZ): tools/view.mk | $(DEPS_STAMP)
	@mkdir -p $(dir $@)
	cd $(dir $@) && npm pack --silent three@$(THREE_VERSION) >/dev/null
	@got="sha512-$$(python3 -c 'import base64,hashlib,sys; print(base64.b64encode(hashlib.sha512(open(sys.argv[1],"rb").read()).digest()).decode())' $@)"; \
	if [ "$$got" != "$(THREE_INTEGRITY)" ]; then \
	  echo "view: three@$(THREE_VERSION) integrity mismatch: $$got"; rm -f $@; exit 1; fi; \
	echo "view: three@$(THREE_VERSION) integrity ok ($(THREE_INTEGRITY))"

$(VIEW_ASSETS)/three.min.js: $(THREE_TGZ)
	@mkdir -p $(dir $@)
	tar -xzf $< -C $(dir $@) --strip-components=2 package/build/three.min.js
	tar -xzf $< -C $(dir $@) --strip-components=4 package/examples/js/controls/OrbitControls.js
	tar -xzf $< -O package/LICENSE > $(dir $@)LICENSE.three
	@touch $@ $(dir $@)OrbitControls.js
$(VIEW_ASSETS)/OrbitControls.js: $(VIEW_ASSETS)/three.min.js
$(VIEW_ASSETS)/view_app.js: tools/view_app.js
	@mkdir -p $(dir $@)
	cp $< $@
view-assets: $(VIEW_ASSETS)/three.min.js $(VIEW_ASSETS)/OrbitControls.js $(VIEW_ASSETS)/view_app.js

# The viewer on a real map (OctoMap's geb079.bt): the page's count against `occmap info`, a
# screenshot in headless Chromium that must not be blank (tests/view_check.sh).
VIEW_MAP := /usr/share/doc/liboctomap-dev/examples/data/geb079.bt
TEST_STEPS += test-view
test-view: $(BUILD)/occmap view-assets
	@bash tests/view_check.sh $(BUILD) $(VIEW_MAP)
.PHONY: view-assets test-view
