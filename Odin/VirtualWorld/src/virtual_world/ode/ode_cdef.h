/* The part of ODE's C API (libode 0.16, double precision) and of odin_step.h that Python sees.
 * Enum values marked "..." are read from ODE's own headers by cffi (API mode), never guessed. */
typedef double dReal;
typedef dReal dVector3[4];
typedef dReal dVector4[4];
typedef dReal dMatrix3[4 * 3];
typedef dReal dQuaternion[4];
typedef uint32_t dTriIndex;

typedef struct dxWorld *dWorldID;
typedef struct dxSpace *dSpaceID;
typedef struct dxBody *dBodyID;
typedef struct dxGeom *dGeomID;
typedef struct dxJoint *dJointID;
typedef struct dxJointGroup *dJointGroupID;
typedef struct dxTriMeshData *dTriMeshDataID;

typedef struct dMass { dReal mass; dVector3 c; dMatrix3 I; } dMass;
typedef struct dContactGeom dContactGeom;   /* opaque here: only C code reads contacts */
typedef struct dJointFeedback { dVector3 f1; dVector3 t1; dVector3 f2; dVector3 t2; } dJointFeedback;

static const double dInfinity;

typedef enum {
  dJointTypeNone, dJointTypeBall, dJointTypeHinge, dJointTypeSlider, dJointTypeContact,
  dJointTypeUniversal, dJointTypeHinge2, dJointTypeFixed, dJointTypeNull, dJointTypeAMotor,
  dJointTypeLMotor, dJointTypePlane2D, dJointTypePR, dJointTypePU, dJointTypePiston, ...
} dJointType;

enum {
  dParamLoStop, dParamHiStop, dParamVel, dParamLoVel, dParamHiVel, dParamFMax,
  dParamFudgeFactor, dParamBounce, dParamCFM, dParamStopERP, dParamStopCFM,
  dParamSuspensionERP, dParamSuspensionCFM, dParamERP, dParamGroup, ...
};
enum { dAMotorUser, dAMotorEuler, ... };

/* init and configuration */
int dInitODE2(unsigned int uiInitFlags);
void dCloseODE(void);
int dCheckConfiguration(const char *token);

/* world */
dWorldID dWorldCreate(void);
void dWorldDestroy(dWorldID);
void dWorldSetGravity(dWorldID, dReal x, dReal y, dReal z);
void dWorldSetERP(dWorldID, dReal erp);
void dWorldSetCFM(dWorldID, dReal cfm);
void dWorldSetQuickStepNumIterations(dWorldID, int num);
void dWorldSetContactMaxCorrectingVel(dWorldID, dReal vel);
void dWorldSetContactSurfaceLayer(dWorldID, dReal depth);
void dWorldSetLinearDamping(dWorldID w, dReal scale);
void dWorldSetAngularDamping(dWorldID w, dReal scale);
void dWorldSetLinearDampingThreshold(dWorldID w, dReal threshold);
void dWorldSetAngularDampingThreshold(dWorldID w, dReal threshold);
void dWorldSetMaxAngularSpeed(dWorldID w, dReal max_speed);

/* spaces and joint groups */
dSpaceID dHashSpaceCreate(dSpaceID space);
dSpaceID dSweepAndPruneSpaceCreate(dSpaceID space, int axisorder);
#define dSAP_AXES_XYZ 36
void dSpaceAdd(dSpaceID, dGeomID);
void dSpaceRemove(dSpaceID, dGeomID);
void dSpaceDestroy(dSpaceID);
void dSpaceSetCleanup(dSpaceID space, int mode);
int dSpaceGetNumGeoms(dSpaceID);
dJointGroupID dJointGroupCreate(int max_size);
void dJointGroupDestroy(dJointGroupID);
void dJointGroupEmpty(dJointGroupID);

/* bodies */
dBodyID dBodyCreate(dWorldID);
void dBodyDestroy(dBodyID);
void dBodySetPosition(dBodyID, dReal x, dReal y, dReal z);
void dBodySetQuaternion(dBodyID, const dQuaternion q);
void dBodySetLinearVel(dBodyID, dReal x, dReal y, dReal z);
void dBodySetAngularVel(dBodyID, dReal x, dReal y, dReal z);
const dReal *dBodyGetPosition(dBodyID);
const dReal *dBodyGetQuaternion(dBodyID);
const dReal *dBodyGetLinearVel(dBodyID);
const dReal *dBodyGetAngularVel(dBodyID);
const dReal *dBodyGetForce(dBodyID);
const dReal *dBodyGetTorque(dBodyID);
void dBodySetMass(dBodyID, const dMass *mass);
void dBodyGetMass(dBodyID, dMass *mass);
void dBodySetKinematic(dBodyID);
void dBodySetDynamic(dBodyID);
dGeomID dBodyGetFirstGeom(dBodyID);
dGeomID dBodyGetNextGeom(dGeomID);
const dReal *dBodyGetRotation(dBodyID);
int dBodyIsEnabled(dBodyID);
void dBodyEnable(dBodyID);
void dBodyDisable(dBodyID);
int dBodyIsKinematic(dBodyID);
void dBodyGetRelPointPos(dBodyID, dReal px, dReal py, dReal pz, dVector3 result);
void dBodyVectorToWorld(dBodyID, dReal px, dReal py, dReal pz, dVector3 result);

/* mass */
void dMassSetZero(dMass *);
void dMassSetParameters(dMass *, dReal themass, dReal cgx, dReal cgy, dReal cgz,
                        dReal I11, dReal I22, dReal I33, dReal I12, dReal I13, dReal I23);
void dMassSetSphereTotal(dMass *, dReal total_mass, dReal radius);
void dMassSetCylinderTotal(dMass *, dReal total_mass, int direction, dReal radius, dReal length);
void dMassSetCapsuleTotal(dMass *, dReal total_mass, int direction, dReal radius, dReal length);
void dMassSetBoxTotal(dMass *, dReal total_mass, dReal lx, dReal ly, dReal lz);
void dMassTranslate(dMass *, dReal x, dReal y, dReal z);
void dMassRotate(dMass *, const dMatrix3 R);
void dMassAdd(dMass *a, const dMass *b);
int dMassCheck(const dMass *m);

/* ODE's random generator (QuickStep reorders constraints with it) */
unsigned long dRandGetSeed(void);
void dRandSetSeed(unsigned long s);

/* rotation */
void dRfromQ(dMatrix3 R, const dQuaternion q);

/* geoms */
void dGeomDestroy(dGeomID geom);
void dGeomSetData(dGeomID geom, void *data);
void dGeomSetBody(dGeomID geom, dBodyID body);
dBodyID dGeomGetBody(dGeomID geom);
void dGeomSetPosition(dGeomID geom, dReal x, dReal y, dReal z);
void dGeomSetQuaternion(dGeomID geom, const dQuaternion Q);
void dGeomSetRotation(dGeomID geom, const dMatrix3 R);
const dReal *dGeomGetRotation(dGeomID geom);
const dReal *dGeomGetPosition(dGeomID geom);
void dGeomGetQuaternion(dGeomID geom, dQuaternion result);
void dGeomSetOffsetPosition(dGeomID geom, dReal x, dReal y, dReal z);
void dGeomSetOffsetQuaternion(dGeomID geom, const dQuaternion Q);
dGeomID dCreateSphere(dSpaceID space, dReal radius);
dGeomID dCreateBox(dSpaceID space, dReal lx, dReal ly, dReal lz);
dGeomID dCreateCylinder(dSpaceID space, dReal radius, dReal length);
dGeomID dCreateCapsule(dSpaceID space, dReal radius, dReal length);
dGeomID dCreatePlane(dSpaceID space, dReal a, dReal b, dReal c, dReal d);
void dGeomPlaneSetParams(dGeomID plane, dReal a, dReal b, dReal c, dReal d);
void dGeomPlaneGetParams(dGeomID plane, dVector4 result);
int dGeomGetClass(dGeomID);
enum { dSphereClass, dBoxClass, dCapsuleClass, dCylinderClass, dPlaneClass, ... };
dTriMeshDataID dGeomTriMeshDataCreate(void);
void dGeomTriMeshDataDestroy(dTriMeshDataID g);
void dGeomTriMeshDataBuildDouble(dTriMeshDataID g, const void *Vertices, int VertexStride,
                                 int VertexCount, const void *Indices, int IndexCount,
                                 int TriStride);
int dGeomTriMeshGetTriangleCount(dGeomID g);
dGeomID dCreateTriMesh(dSpaceID space, dTriMeshDataID Data, void *Callback, void *ArrayCallback,
                       void *RayCallback);

/* joints */
void dJointDestroy(dJointID);
void dJointAttach(dJointID, dBodyID body1, dBodyID body2);
void dJointSetFeedback(dJointID, dJointFeedback *);
int dJointGetType(dJointID);
dBodyID dJointGetBody(dJointID, int index);
int dAreConnected(dBodyID, dBodyID);
dJointID dJointCreateBall(dWorldID, dJointGroupID);
dJointID dJointCreateHinge(dWorldID, dJointGroupID);
dJointID dJointCreateSlider(dWorldID, dJointGroupID);
dJointID dJointCreatePiston(dWorldID, dJointGroupID);
dJointID dJointCreateUniversal(dWorldID, dJointGroupID);
dJointID dJointCreateHinge2(dWorldID, dJointGroupID);
dJointID dJointCreatePR(dWorldID, dJointGroupID);
dJointID dJointCreatePU(dWorldID, dJointGroupID);
dJointID dJointCreateFixed(dWorldID, dJointGroupID);
dJointID dJointCreatePlane2D(dWorldID, dJointGroupID);
dJointID dJointCreateAMotor(dWorldID, dJointGroupID);
dJointID dJointCreateLMotor(dWorldID, dJointGroupID);

void dJointSetBallAnchor(dJointID, dReal x, dReal y, dReal z);
void dJointSetHingeAnchor(dJointID, dReal x, dReal y, dReal z);
void dJointSetHingeAxis(dJointID, dReal x, dReal y, dReal z);
void dJointSetSliderAxis(dJointID, dReal x, dReal y, dReal z);
void dJointSetPistonAnchor(dJointID, dReal x, dReal y, dReal z);
void dJointSetPistonAxis(dJointID, dReal x, dReal y, dReal z);
void dJointSetUniversalAnchor(dJointID, dReal x, dReal y, dReal z);
void dJointSetUniversalAxis1(dJointID, dReal x, dReal y, dReal z);
void dJointSetUniversalAxis2(dJointID, dReal x, dReal y, dReal z);
void dJointSetHinge2Anchor(dJointID, dReal x, dReal y, dReal z);
void dJointSetHinge2Axes(dJointID j, const dReal *axis1, const dReal *axis2);
void dJointSetPRAnchor(dJointID, dReal x, dReal y, dReal z);
void dJointSetPRAxis1(dJointID, dReal x, dReal y, dReal z);
void dJointSetPRAxis2(dJointID, dReal x, dReal y, dReal z);
void dJointSetPUAnchor(dJointID, dReal x, dReal y, dReal z);
void dJointSetPUAxis1(dJointID, dReal x, dReal y, dReal z);
void dJointSetPUAxis2(dJointID, dReal x, dReal y, dReal z);
void dJointSetPUAxis3(dJointID, dReal x, dReal y, dReal z);
void dJointSetFixed(dJointID);

void dJointGetHingeAxis(dJointID, dVector3 result);
void dJointGetSliderAxis(dJointID, dVector3 result);
void dJointGetPistonAxis(dJointID, dVector3 result);
void dJointGetUniversalAxis1(dJointID, dVector3 result);
void dJointGetUniversalAxis2(dJointID, dVector3 result);
void dJointGetHinge2Axis1(dJointID, dVector3 result);
void dJointGetHinge2Axis2(dJointID, dVector3 result);
void dJointGetPRAxis1(dJointID, dVector3 result);
void dJointGetPRAxis2(dJointID, dVector3 result);
void dJointGetPUAxis1(dJointID, dVector3 result);
void dJointGetPUAxis2(dJointID, dVector3 result);
void dJointGetPUAxis3(dJointID, dVector3 result);

dReal dJointGetHingeAngle(dJointID);
dReal dJointGetHingeAngleRate(dJointID);
dReal dJointGetSliderPosition(dJointID);
dReal dJointGetSliderPositionRate(dJointID);
dReal dJointGetPistonPosition(dJointID);
dReal dJointGetPistonPositionRate(dJointID);
dReal dJointGetPistonAngle(dJointID);
dReal dJointGetPistonAngleRate(dJointID);
dReal dJointGetUniversalAngle1(dJointID);
dReal dJointGetUniversalAngle2(dJointID);
dReal dJointGetUniversalAngle1Rate(dJointID);
dReal dJointGetUniversalAngle2Rate(dJointID);
dReal dJointGetHinge2Angle1(dJointID);
dReal dJointGetHinge2Angle2(dJointID);
dReal dJointGetHinge2Angle1Rate(dJointID);
dReal dJointGetHinge2Angle2Rate(dJointID);
dReal dJointGetPRPosition(dJointID);
dReal dJointGetPRPositionRate(dJointID);
dReal dJointGetPRAngle(dJointID);
dReal dJointGetPRAngleRate(dJointID);
dReal dJointGetPUPosition(dJointID);
dReal dJointGetPUPositionRate(dJointID);
dReal dJointGetPUAngle1(dJointID);
dReal dJointGetPUAngle2(dJointID);
dReal dJointGetPUAngle1Rate(dJointID);
dReal dJointGetPUAngle2Rate(dJointID);

void dJointSetHingeParam(dJointID, int parameter, dReal value);
dReal dJointGetHingeParam(dJointID, int parameter);
void dJointSetSliderParam(dJointID, int parameter, dReal value);
dReal dJointGetSliderParam(dJointID, int parameter);
void dJointSetPistonParam(dJointID, int parameter, dReal value);
dReal dJointGetPistonParam(dJointID, int parameter);
void dJointSetUniversalParam(dJointID, int parameter, dReal value);
dReal dJointGetUniversalParam(dJointID, int parameter);
void dJointSetHinge2Param(dJointID, int parameter, dReal value);
dReal dJointGetHinge2Param(dJointID, int parameter);
void dJointSetPRParam(dJointID, int parameter, dReal value);
dReal dJointGetPRParam(dJointID, int parameter);
void dJointSetPUParam(dJointID, int parameter, dReal value);
dReal dJointGetPUParam(dJointID, int parameter);
void dJointSetBallParam(dJointID, int parameter, dReal value);
dReal dJointGetBallParam(dJointID, int parameter);
void dJointSetFixedParam(dJointID, int parameter, dReal value);
dReal dJointGetFixedParam(dJointID, int parameter);
void dJointSetAMotorParam(dJointID, int parameter, dReal value);
void dJointSetLMotorParam(dJointID, int parameter, dReal value);
dReal dJointGetAMotorParam(dJointID, int parameter);
dReal dJointGetLMotorParam(dJointID, int parameter);

void dJointSetAMotorMode(dJointID, int mode);
void dJointSetAMotorNumAxes(dJointID, int num);
void dJointSetAMotorAxis(dJointID, int anum, int rel, dReal x, dReal y, dReal z);
void dJointSetLMotorNumAxes(dJointID, int num);
void dJointSetLMotorAxis(dJointID, int anum, int rel, dReal x, dReal y, dReal z);

/* Category and collide bits (the space skips pairs whose bits do not meet). */
void dGeomSetCategoryBits(dGeomID, unsigned long bits);
unsigned long dGeomGetCategoryBits(dGeomID);
void dGeomSetCollideBits(dGeomID, unsigned long bits);

/* Odin's own declarations follow, taken from odin_step.h by build_ode.py (one source). */
