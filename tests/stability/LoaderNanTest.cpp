// S.4 case 5 at the loading boundary: a glTF file carrying a NaN position is rejected with an error
// naming the mesh and vertex; a NaN normal is repaired (finalizeScene) and the loaded scene renders
// clean. The in-memory NaN meshes of CasesTest bypass this boundary on purpose.
#include <cmath>

#include "../unit/scene/GltfBuilder.h"
#include "StabilityLab.h"
#include "core/Error.h"
#include "scene/SceneLoader.h"

using namespace gis;
using namespace gis::stability;

namespace {

class LoaderCell : public ::testing::Test {
protected:
    void SetUp() override { beginCell("C05_DegenerateAndNan", "loader"); }
    void TearDown() override { endCell(HasFailure(), IsSkipped()); }
};

} // namespace

TEST_F(LoaderCell, RejectsNanPositionsAndRepairsNanNormals) {
    test::TempDir dir;
    {
        test::GltfBuilder b;
        const int pos = b.addVec3s({{0, 0, 0}, {std::nanf(""), 0, 0}, {0, 0, -1}});
        b.setScene({b.addNode({{"mesh", b.addMesh("nan_position", {{"attributes", {{"POSITION", pos}}}})}})});
        const std::string path = b.writeGlb(dir, "nan_position.glb");
        try {
            loadScene(path);
            ADD_FAILURE() << "a NaN position must be rejected";
        } catch (const InputError& e) {
            const std::string what = e.what();
            EXPECT_NE(what.find("mesh 'nan_position'"), std::string::npos) << what;
            EXPECT_NE(what.find("position 1 is not finite"), std::string::npos) << what;
            note("NaN position", "rejected: " + what.substr(what.find("mesh")));
        }
    }
    {
        test::GltfBuilder b;
        const int pos = b.addVec3s({{-1, 0, -1}, {1, 0, -1}, {0, 0, 1}});
        const int nrm = b.addVec3s({{0, 1, 0}, {std::nanf(""), std::nanf(""), std::nanf("")}, {0, 1, 0}});
        b.setScene({b.addNode(
            {{"mesh", b.addMesh("nan_normal", {{"attributes", {{"POSITION", pos}, {"NORMAL", nrm}}}})}})});
        const Scene s = loadScene(b.writeGltf(dir, "nan_normal.gltf"));
        ASSERT_EQ(s.meshes.size(), 1u);
        for (const glm::vec3& n : s.meshes[0].normals) {
            EXPECT_TRUE(std::isfinite(n.x) && std::isfinite(n.y) && std::isfinite(n.z));
            EXPECT_NEAR(glm::length(n), 1.0f, 1e-4f);
        }
        note("NaN normal", "repaired to the face normal");
    }
}
